"""LiDAR-inertial odometry: IMU integration against closed-form motion, the filter's update on
known planes, the time checks, and the backend on the simulated UAV mission's first scans."""

import itertools
import re
from dataclasses import replace

import numpy as np
import pytest
from scipy.spatial.transform import Rotation
from support.missions import first_scans_folder

from alte.errors import ParameterError, RegistrationError
from alte.io.bags.bag import FrameStream, ReadSettings
from alte.io.bags.imu import ImuSamples, read_imu
from alte.metrics.trajectory import trajectory_errors
from alte.registration.inertial import (
    GRAVITY,
    ImuNoise,
    InertialFilter,
    NavState,
    integrate,
    still,
    strong_directions,
)
from alte.registration.lio import LioOdometry, LioSettings, check_overlap
from alte.registration.localmap import LocalMap
from alte.registration.odometry import (
    OdometrySettings,
    PoseCounts,
    lio_settings,
    odometry_frames,
    odometry_label,
    odometry_params,
    resolve_method,
)
from alte.sim import get_terrain, true_poses
from alte.sim.profile import PROFILES
from alte.sim.scenario import ensure_terrain
from alte.types import Mount

RATE = 200.0
T0 = 1_700_000_000_000_000_000


def _stream(seconds: float, gyro: np.ndarray, force) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """IMU samples at 200 Hz from ``T0``: constant ``gyro``, ``force(t)`` (N, 3)."""
    t = np.arange(int(seconds * RATE) + 2) / RATE
    stamps = T0 + np.round(t * 1e9).astype(np.int64)
    return stamps, np.tile(gyro, (len(t), 1)), force(t)


def _rest(velocity=(0.0, 0.0, 0.0)) -> NavState:
    return NavState(T0, Rotation.identity(), np.zeros(3), np.array(velocity, float),
                    np.zeros(3), np.zeros(3))


def test_constant_velocity_and_yaw_rate_integrate_to_the_closed_form():
    """Level flight at (2, 1, 0) m/s turning at 0.5 rad/s: the accelerometer reads +9.81 on
    z (no acceleration), so after 2 s the body is at (4, 2, 0) with a yaw of 1 rad."""
    stamps, gyro, accel = _stream(2.0, np.array([0.0, 0.0, 0.5]),
                                  lambda t: np.tile(-GRAVITY, (len(t), 1)))
    end = integrate(_rest((2.0, 1.0, 0.0)), T0 + 2_000_000_000, stamps, gyro, accel)
    assert np.abs(end.position - [4.0, 2.0, 0.0]).max() < 1e-9
    assert np.abs(end.rotation.as_rotvec() - [0.0, 0.0, 1.0]).max() < 1e-9
    assert end.stamp == T0 + 2_000_000_000


def test_constant_acceleration_seen_by_a_spinning_body_integrates_to_half_a_t_squared():
    """World acceleration (1, 0, 0) m/s^2 while the body spins at 0.8 rad/s about z: the
    accelerometer sees it rotate in its own frame; 2 s later x = 2 m, v = (2, 0, 0)."""
    rate = 0.8

    def force(t: np.ndarray) -> np.ndarray:
        return Rotation.from_rotvec(np.outer(t, [0, 0, rate])).inv().apply([1.0, 0.0, 9.81])

    stamps, gyro, accel = _stream(2.0, np.array([0.0, 0.0, rate]), force)
    end = integrate(_rest(), T0 + 2_000_000_000, stamps, gyro, accel)
    assert np.abs(end.position - [2.0, 0.0, 0.0]).max() < 2e-3
    assert np.abs(end.velocity - [2.0, 0.0, 0.0]).max() < 2e-3


def test_imu_on_another_clock_is_a_typed_error():
    """Scan stamps in ns against IMU stamps in microseconds: no sample in any scan interval
    (what made a package's trial count zero IMU samples per scan), so it is refused."""
    stamps = np.arange(10, dtype=np.int64) * 5_000 + T0 // 1000
    imu = ImuSamples(stamps, np.zeros((10, 3)), np.tile(-GRAVITY, (10, 1)))
    with pytest.raises(RegistrationError, match=r"outside the IMU topic.*another clock or unit"):
        check_overlap(imu, T0)
    check_overlap(ImuSamples(stamps * 1000, np.zeros((10, 3)), np.zeros((10, 3))), T0)


def _planes(rng: np.random.Generator, walls: bool) -> np.ndarray:
    g = rng.uniform(-15, 15, (6000, 2))
    ground = np.c_[g, np.zeros(len(g))]
    if not walls:
        return ground
    return np.vstack([ground, np.c_[g[:, 0], np.full(len(g), 15.0), g[:, 1] / 2 + 7.5],
                      np.c_[np.full(len(g), 15.0), g[:, 0], g[:, 1] / 2 + 7.5]])


def _update(walls: bool, offset: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Position and rotation error after one update from a state ``offset`` from the truth
    (rotation vector, position) with the truth's scan of the planes."""
    rng = np.random.default_rng(3)
    world = _planes(rng, walls)
    local = LocalMap(0.25, 100.0)
    local.add(world, np.zeros(3))
    truth = NavState(T0, Rotation.from_rotvec([0.01, -0.02, 0.3]), np.array([1.0, -2.0, 6.0]),
                     np.zeros(3), np.zeros(3), np.zeros(3))
    scan = truth.rotation.inv().apply(world[rng.choice(len(world), 1500)] - truth.position)
    scan += rng.normal(0.0, 0.01, scan.shape)
    start = InertialFilter(truth, ImuNoise()).apply(np.r_[offset, np.zeros(9)], truth)
    lio = object.__new__(LioOdometry)
    lio.map, lio.settings = local, LioSettings(max_distance=2.0)
    filt = InertialFilter(start, ImuNoise())
    filt.cov = np.diag(np.r_[np.full(3, 0.05**2), np.full(3, 0.5**2), np.ones(9)])
    lio.filter = filt
    assert filt.update(lio._residuals(scan), 0.05, 10) > 100
    return (filt.state.position - truth.position,
            (filt.state.rotation.inv() * truth.rotation).as_rotvec())


def test_update_on_three_planes_recovers_the_pose():
    dp, dr = _update(True, np.array([0.01, -0.01, 0.02, 0.3, -0.2, 0.25]))
    assert np.abs(dp).max() < 0.01 and np.degrees(np.abs(dr).max()) < 0.05


def _along_track_sigma(placed: float) -> tuple[float, float]:
    """Posterior x sigma and x error after one update over exact flat ground and a wall
    across the track (normal x, six map points) placed with x variance ``placed``, from a
    state 0.3 m behind the truth with 0.5 m of prior sigma."""
    rng = np.random.default_rng(8)
    g = rng.uniform(-15, 15, (6000, 2))
    ground = np.c_[g, np.zeros(len(g))]
    wall = np.c_[np.full(6, 15.0), rng.uniform(-1.0, 1.0, 6), rng.uniform(4.0, 6.0, 6)]
    local = LocalMap(0.25, 100.0)
    local.add(ground, np.zeros(3))
    local.add(np.vstack([wall, wall + np.array([0.0, 0.0, 0.3])]), np.zeros(3),
              np.array([placed, 0.0, 0.0]))
    truth = NavState(T0, Rotation.identity(), np.array([0.0, 0.0, 6.0]), np.zeros(3),
                     np.zeros(3), np.zeros(3))
    scan = np.vstack([ground[rng.choice(len(ground), 1500)], wall]) - truth.position
    lio = object.__new__(LioOdometry)
    lio.map, lio.settings = local, LioSettings(plane_sigma=0.05, max_distance=2.0, gate=10.0)
    filt = InertialFilter(replace(truth, position=truth.position - [0.3, 0.0, 0.0]),
                          ImuNoise())
    filt.cov = np.diag(np.r_[np.full(3, 0.01**2), np.full(3, 0.5**2), np.ones(9)])
    lio.filter = filt
    filt.update(lio._residuals(scan), lio.settings.plane_sigma, 10)
    return float(np.sqrt(filt.cov[3, 3])), float(filt.state.position[0] - truth.position[0])


def test_a_wall_mapped_while_uncertain_places_the_vehicle_no_better_than_that():
    """Six points of a wall placed exactly fix the along-track position to centimetres; the
    same points placed while x was uncertain by 0.5 m leave it uncertain by 0.2 m (a wall
    the drift itself mapped is no absolute fix)."""
    sigma, error = _along_track_sigma(0.0)
    assert sigma < 0.03 and abs(error) < 0.01
    sigma, _ = _along_track_sigma(0.25)
    assert 0.15 < sigma < 0.3


def _gated(position_sigma: float) -> int:
    """Residuals kept of a scan 0.5 m in front of a mapped wall (a parallel face the
    scan's own wall is not mapped yet), the state at the truth with that prior."""
    rng = np.random.default_rng(5)
    local = LocalMap(0.25, 100.0)
    local.add(np.c_[np.full(4000, 15.0), rng.uniform(-10, 10, (4000, 2))], np.zeros(3))
    truth = NavState(T0, Rotation.identity(), np.zeros(3), np.zeros(3), np.zeros(3),
                     np.zeros(3))
    scan = np.c_[np.full(500, 14.5), rng.uniform(-8, 8, (500, 2))]
    lio = object.__new__(LioOdometry)
    lio.map, lio.settings = local, LioSettings(max_distance=2.0)
    lio.filter = InertialFilter(truth, ImuNoise())
    lio.filter.cov[:6, :6] = np.diag(np.r_[np.full(3, 1e-3**2), np.full(3, position_sigma**2)])
    r, _ = lio._residuals(scan)(truth)
    return len(r)


def test_residuals_beyond_what_the_prior_allows_are_gated():
    assert _gated(0.01) == 0  # 0.5 m off with a pose known to 1 cm: another surface
    assert _gated(0.5) == 500  # with a pose known to 0.5 m it may be this wall


def test_the_filter_starts_knowing_its_heading_not_its_tilt():
    """The world frame is the first pose's heading: yaw has no uncertainty at the start;
    roll and pitch against gravity do (0.02 rad)."""
    rotation = Rotation.from_euler("ZYX", [40.0, 10.0, -5.0], degrees=True)
    state = NavState(T0, rotation, np.zeros(3), np.zeros(3), np.zeros(3), np.zeros(3))
    world = rotation.as_matrix() @ InertialFilter(state, ImuNoise()).cov[0:3, 0:3] \
        @ rotation.as_matrix().T
    assert np.sqrt(world[2, 2]) == pytest.approx(1e-3)
    assert np.sqrt(np.diag(world)[:2]) == pytest.approx([0.02, 0.02])


def test_update_on_flat_ground_keeps_what_the_ground_cannot_see():
    """Only a ground plane: z, roll and pitch are corrected, x, y and yaw keep the prediction
    (a LiDAR-only odometry would slide there)."""
    dp, dr = _update(False, np.array([0.01, -0.01, 0.02, 0.3, -0.2, 0.25]))
    assert abs(dp[2]) < 0.01 and np.degrees(np.abs(dr[:2]).max()) < 0.05
    assert abs(dp[0] - 0.3) < 0.02 and abs(dp[1] + 0.2) < 0.02  # the prior's offset stays
    assert abs(np.degrees(dr[2]) + np.degrees(0.02)) < 0.05


def test_auto_is_lio_with_an_imu_and_lio_without_one_is_refused():
    assert OdometrySettings().method == "auto"
    assert resolve_method(OdometrySettings(), True).method == "lio"
    assert resolve_method(OdometrySettings(), False).method == "kiss"
    assert resolve_method(odometry_params("plane"), True).method == "plane"
    with pytest.raises(ParameterError, match="odometry: method=lio needs an IMU topic"):
        list(odometry_frames([], Mount(), counts=PoseCounts(), params=odometry_params("lio")))
    with pytest.raises(ParameterError, match=r"plane_sigma=-1\.0 out of range"):
        odometry_params("lio", {"plane_sigma": "-1"})


@pytest.fixture(scope="module")
def uav_mission(tmp_path_factory):
    """The first 50 scans (5 s, consecutive) of the SIM NAV 1 mission under the uav
    profile, as the whole mission simulates them (the whole one: 5 CPU s more)."""
    return first_scans_folder(tmp_path_factory.mktemp("lio") / "sim_nav_1", "sim_nav_1", 50,
                              profile=PROFILES["uav"])


def test_lio_flies_the_first_five_seconds_of_the_uav_mission(uav_mission):
    """50 scans (5 s, 24 m): LiDAR-inertial ATE 5 mm, 3 mm off at the last scan, against
    the simulator's truth (KISS-ICP over the whole mission: 34 m; docs/results/lio.md). The filter
    starts from the IMU's 2 s at rest before the first scan (biases, zero velocity);
    without that start it had to learn the accelerometer bias while x and y were not
    yet seen, and was 0.95 m off here."""
    bag = uav_mission / "bag"
    stream = FrameStream(bag, ReadSettings(pose_topic="", allow_no_pose=True))
    imu = read_imu(bag)
    truth = true_poses(get_terrain("sim_nav_1"))
    counts = PoseCounts()
    frames = list(itertools.islice(odometry_frames(
        stream, stream.mount, counts=counts, imu=imu,
        start=(truth.positions[0], truth.quaternions[0])), 50))
    assert counts.method == "lio" and counts.deskewed == 50
    assert 1.9 < counts.rest_s <= 2.0  # the IMU's 2 s before the first scan, less the set-off
    stamps = np.array([f.stamp for f in frames])
    j = np.searchsorted(truth.stamps, stamps)
    errors = trajectory_errors(stamps, np.array([f.position for f in frames]),
                               np.array([f.quaternion for f in frames]),
                               truth.positions[j], truth.quaternions[j])
    assert errors.ate_m < 0.05
    final = np.linalg.norm(frames[-1].position - truth.positions[j[-1]])
    assert final < 0.05


def _mesh_median(frame, mount, mesh) -> float:
    """Median distance (m) of a frame's points, placed by its pose, to the true mesh."""
    from alte.sim import mesh_distance

    sensor = frame.points @ mount.rotation.as_matrix().T + mount.translation
    world = Rotation.from_quat(frame.quaternion).apply(sensor) + frame.position
    return float(np.median(mesh_distance(world[np.isfinite(world).all(axis=1)], mesh)))


def test_lio_frames_carry_the_scan_the_imu_deskewed(uav_mission):
    """The frames LIO yields hold the scan deskewed to the stamp (no per-point time left):
    the first scan, pitching at 14 deg/s, lies 1 cm from the true mesh (median) at the
    exact start pose; as taken it lies 0.28 m off (the cloud the map was built from until
    odometry frames carried their points deskewed)."""
    from alte.sim import load_ground_truth

    bag = uav_mission / "bag"
    stream = FrameStream(bag, ReadSettings(pose_topic="", allow_no_pose=True))
    truth = true_poses(get_terrain("sim_nav_1"))
    mesh = load_ground_truth(uav_mission)
    raw = next(iter(stream))
    first = next(odometry_frames(stream, stream.mount, counts=PoseCounts(), imu=read_imu(bag),
                                 start=(truth.positions[0], truth.quaternions[0])))
    assert first.times is None and first.points.shape == raw.points.shape
    assert _mesh_median(first, stream.mount, mesh) < 0.02  # the range noise: 0.03 m sigma
    as_taken = replace(raw, position=first.position, quaternion=first.quaternion)
    assert _mesh_median(as_taken, stream.mount, mesh) > 0.2


def test_the_pipeline_picks_lio_for_a_bag_with_an_imu_and_says_so(tmp_path, capsys):
    """``--poses odometry`` on the uav profile's bag (it has /imu) runs LIO unasked; on the
    thesis profile's bag (no IMU) KISS-ICP; ``alte register`` prints which. The uav bag
    holds the mission's first 3 scans: over 3 spread over it each LIO run integrated 50 s
    of IMU (4 CPU s)."""
    from alte.cli import main
    from alte.pipeline import FrameSettings, PoseSource, open_input, prepare

    uav = first_scans_folder(tmp_path / "uav", "sim_lan_2", 3, profile=PROFILES["uav"])
    thesis = ensure_terrain("sim_lan_2", tmp_path, frames=3)
    spec = FrameSettings(poses=PoseSource.ODOMETRY)
    lio, kiss = (prepare(open_input(f), spec).counts for f in (uav, thesis))
    assert lio.poses.method == "lio" and lio.poses.deskewed == 3
    assert any("LiDAR-inertial odometry (lidar-inertial, IMU imu_link at 200 Hz)" in n
               for n in lio.notes)
    assert kiss.poses.method == "kiss" and not any("inertial" in n for n in kiss.notes)
    assert main(["register", str(uav), "--poses", "odometry", "--out",
                 str(tmp_path / "cloud.ply")]) == 0
    out = capsys.readouterr().out
    assert re.search(r"odometry \(lidar-inertial, \d+ ms per scan, IMU biases from 1\.9 s at "
                     r"rest, 3 scans deskewed\)", out)
    assert kiss.poses.rest_s == 0.0


def _rings(rng: np.random.Generator, spacing: float, angle: float) -> np.ndarray:
    """Ground as a scan sees it: lines (rings) ``spacing`` apart, 3 cm of range noise."""
    t, k = rng.uniform(-12, 12, 30000), rng.integers(-15, 16, 30000) * spacing
    c, s = np.cos(angle), np.sin(angle)
    return np.c_[t * c - k * s, t * s + k * c, rng.normal(0.0, 0.03, len(t))]


def test_a_wide_plane_fit_spans_scan_rings_and_keeps_the_five_point_planes():
    """Two scans' rings 0.7 m apart: a point's five nearest map points lie along one ring
    (a line, refused), so almost no ground point gets a plane; twenty within 3 m span
    rings and fit one, tilted by about a degree. Near a building's corner every plane the
    five points found is kept."""
    rng = np.random.default_rng(5)
    local = LocalMap(0.25, 100.0)
    local.add(np.vstack([_rings(rng, 0.7, 0.0), _rings(rng, 0.7, 0.5)]), np.zeros(3))
    query = np.c_[rng.uniform(-8, 8, (500, 2)), np.zeros(500)]
    assert len(local.planes(query, 2.0, 5).index) < 25
    wide = local.planes(query, 2.0, 5, (20, 3.0))
    assert len(wide.index) > 450
    assert np.degrees(np.arcsin(np.linalg.norm(wide.normal[:, :2], axis=1))).mean() < 2.0
    rng, local = np.random.default_rng(5), LocalMap(0.25, 100.0)
    corner = np.vstack([  # two walls of a building meeting at (3, 1)
        np.c_[np.full(3000, 3.0), rng.uniform(-1, 1, 3000), rng.uniform(0.5, 2.5, 3000)],
        np.c_[rng.uniform(3, 5, 3000), np.full(3000, 1.0), rng.uniform(0.5, 2.5, 3000)]])
    local.add(corner, np.zeros(3))
    probe = np.c_[np.full(20, 3.0), rng.uniform(0.3, 0.6, 20), rng.uniform(1.2, 1.8, 20)]
    five = local.planes(probe, 2.0, 5).index
    wide = local.planes(probe, 2.0, 5, (20, 3.0))
    assert len(five) > 0 and set(five) <= set(wide.index)
    assert np.abs(wide.normal[:, 0]).min() > 0.99


def test_weak_directions_of_flat_ground_are_projected_out_and_walls_keep_all_six():
    """Residuals of noisy flat ground inform z, roll and pitch; x, y and yaw only through
    tilted normals, below the threshold: the projector drops them. Three planes keep all."""
    rng = np.random.default_rng(7)
    for walls, kept in ((False, 3), (True, 6)):
        world = _planes(rng, walls)
        normal = np.zeros_like(world)
        normal[:, 2] = 1.0
        if walls:
            normal[6000:12000], normal[12000:] = [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]
        normal[:, :2] += rng.normal(0.0, 0.02, (len(world), 2)) * (normal[:, 2:] > 0)
        normal /= np.linalg.norm(normal, axis=1, keepdims=True)
        scan = world[::6] - [0.0, 0.0, 10.0]
        jac = np.hstack([np.cross(scan, normal[::6]), normal[::6]])
        projector = strong_directions(jac, np.full(len(jac), 1 / 0.15**2), 30.0)
        assert round(np.trace(projector)) == kept
        if not walls:
            for axis in (2, 3, 4):  # yaw, x, y
                assert np.linalg.norm(projector @ np.eye(6)[axis]) < 0.01


def test_the_plane_fit_across_rings_and_the_projection_are_odometry_settings():
    """``--odometry-set wide_points=0 least=0`` is the filter before both (small plane fits,
    every direction updated)."""
    before = lio_settings(odometry_params("lio", {"wide_points": "0", "least": "0"}))
    assert (before.wide_points, before.least) == (0, 0.0)
    default = lio_settings(odometry_params("lio", {}))
    assert (default.wide_points, default.wide_reach, default.least) == (20, 3.0, 30.0)
    assert lio_settings(odometry_params("lio", {"wide_reach": "4"})).wide_reach == 4.0


#: LIO settings refused (``odometry_params(METHOD, {KEY: VALUE})``), and the message.
REFUSED = [
    ("lio", "wide_points", "2", r"odometry: wide_points=2 out of range \(0 or >= 3\)"),
    ("lio", "least", "-1", r"odometry: least=-1.0 out of range \(>= 0\)"),
    ("kiss", "least", "5", r"odometry: least: not a setting of method=kiss"),
    ("lio", "gyro_bias", "0", r"odometry: gyro_bias=0.0 out of range \(> 0\)"),
    ("kiss", "accel_walk", "1e-3", r"odometry: accel_walk: not a setting of method=kiss"),
]


@pytest.mark.parametrize(("method", "key", "value", "message"), REFUSED)
def test_lio_settings_out_of_range_or_of_another_backend_are_refused_naming_the_setting(
        method, key, value, message):
    with pytest.raises(ParameterError, match=message):
        odometry_params(method, {key: value})


def _at_rest(rng: np.random.Generator, seconds: float, attitude: Rotation, gyro_bias: np.ndarray,
             accel_bias: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Gyroscope and accelerometer samples (200 Hz, the uav profile's white noise) of a
    still IMU in ``attitude``."""
    noise, count = ImuNoise(), int(seconds * RATE)
    gyro = gyro_bias + rng.normal(0.0, noise.gyro * np.sqrt(RATE), (count, 3))
    force = attitude.inv().apply(-GRAVITY) + accel_bias
    return gyro, force + rng.normal(0.0, noise.accel * np.sqrt(RATE), (count, 3))


def test_rest_is_the_still_samples_before_motion_and_never_a_steady_turn():
    rng, noise = np.random.default_rng(3), ImuNoise()
    level = Rotation.identity()
    gyro, accel = _at_rest(rng, 2.0, level, np.full(3, 0.005), np.full(3, 0.1))
    assert still(gyro, accel, noise, RATE) == 400
    moving = gyro.copy()
    moving[300:, 1] += 0.26  # pitching at 15 deg/s after 1.5 s
    assert still(moving, accel, noise, RATE) == 300
    assert still(gyro[:80], accel[:80], noise, RATE) == 0  # 0.4 s is too short
    assert still(gyro + np.array([0.0, 0.0, 0.1]), accel, noise, RATE) == 0  # a steady turn
    # a 3.2-sigma yaw bias (1.6 deg/s) is a bias, one of 4.7 sigmas (2.3 deg/s) a turn
    assert still(gyro + np.array([0.0, 0.0, 0.0276]), accel, noise, RATE) == 400
    assert still(gyro + np.array([0.0, 0.0, 0.041]), accel, noise, RATE) == 0
    shaken = accel + rng.normal(0.0, 0.5, accel.shape)
    assert still(gyro, shaken, noise, RATE) == 0


def test_the_imus_figures_are_odometry_settings_and_decide_what_a_rest_is():
    """A flight controller's IMU is not the ADIS16448: ``--odometry-set gyro_bias=...`` (and
    the five other Kalibr figures) reach the filter, so a still IMU whose turn-on bias is
    2.9 deg/s (5.8 of the ADIS's sigmas: a turn) is a rest when its own sigma is 1 deg/s."""
    default = lio_settings(odometry_params("lio", {}))
    assert default.noise == ImuNoise()
    mine = lio_settings(odometry_params("lio", {
        "gyro_noise": "5e-4", "accel_noise": "6e-3", "gyro_walk": "1e-4", "accel_walk": "3e-3",
        "gyro_bias": "0.0175", "accel_bias": "0.5"}))
    assert mine.noise == ImuNoise(5e-4, 6e-3, 1e-4, 3e-3, 0.0175, 0.5)
    assert odometry_label(odometry_params("lio", {"accel_walk": "3e-3"})) \
        == "lidar-inertial accel_walk=0.003"
    rng = np.random.default_rng(5)
    gyro, accel = _at_rest(rng, 2.0, Rotation.identity(), np.array([0.0, 0.0, 0.0506]),
                           np.zeros(3))
    assert still(gyro, accel, default.noise, RATE) == 0
    assert still(gyro, accel, mine.noise, RATE) == 400


def test_settling_at_rest_finds_the_biases_and_the_ground_corrects_the_accelerometer():
    """At rest the accelerometer bias is the force less gravity in the believed attitude:
    a 0.01 rad roll error makes it 0.098 m/s^2 wrong along y. When a roll fix arrives
    (the LiDAR's ground), the settled covariance corrects the bias with it."""
    rng = np.random.default_rng(4)
    truth = Rotation.from_rotvec([0.02, -0.03, 1.0])
    gyro_bias, accel_bias = np.array([0.004, -0.006, 0.002]), np.array([0.15, -0.2, 0.1])
    gyro, accel = _at_rest(rng, 2.0, truth, gyro_bias, accel_bias)
    believed = truth * Rotation.from_rotvec([0.01, 0.0, 0.0])
    state = NavState(T0, believed, np.zeros(3), np.array([0.5, 0.0, 0.0]), np.zeros(3),
                     np.zeros(3))
    flt = InertialFilter(state, ImuNoise())
    flt.settle(gyro, accel)
    assert np.abs(flt.state.gyro_bias - gyro_bias).max() < 5e-4
    assert np.abs(flt.state.velocity).max() == 0.0
    assert np.abs(flt.state.accel_bias - accel_bias).max() > 0.08

    def attitude(current: NavState) -> tuple[np.ndarray, np.ndarray]:
        """The attitude error, twice (an update needs six residuals)."""
        error = (truth.inv() * current.rotation).as_rotvec()
        return np.tile(error, 2), np.tile(np.hstack([np.eye(3), np.zeros((3, 3))]), (2, 1))

    assert flt.update(attitude, 1e-4) == 6
    assert np.abs(flt.state.accel_bias - accel_bias).max() < 0.01


def test_the_uav_mission_starts_the_filter_at_rest(uav_mission):
    bag = uav_mission / "bag"
    stream = FrameStream(bag, ReadSettings(pose_topic="", allow_no_pose=True))
    imu = read_imu(bag)
    first = next(iter(stream))
    odometry = LioOdometry(imu, stream.mount, LioSettings(), None, first.stamp)
    assert odometry.rest_s > 1.9
    assert np.abs(odometry.filter.state.velocity).max() < 0.05
    settled = imu.angular_velocity[imu.stamps < first.stamp - 100_000_000].mean(axis=0)
    assert np.abs(odometry.filter.state.gyro_bias - settled).max() < 1e-3
    late = LioOdometry(imu, stream.mount, LioSettings(), None, first.stamp + 3_000_000_000)
    assert late.rest_s == 0.0  # the 2 s before are flight: no rest, the old start


def test_lio_settings_are_a_checked_record_naming_the_field():
    """The LIO's settings keep the bounds of the odometry settings they come from, and its
    internals (gate, iterations) are checked as well; text converts (trial scripts)."""
    assert LioSettings.parse({"gate": "4", "iterations": "3"}).iterations == 3
    with pytest.raises(ParameterError, match=r"lio: neighbours=2 out of range \(neighbours >= 3\)"):
        LioSettings(neighbours=2)
    with pytest.raises(ParameterError, match=r"lio: iterations=0 out of range"):
        replace(LioSettings(), iterations=0)
    with pytest.raises(ParameterError, match=r"lio: noise: imu noise: gyro=0.0 out of range"):
        LioSettings.parse({"noise": {"gyro": 0}})
