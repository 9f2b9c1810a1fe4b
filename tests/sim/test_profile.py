"""Sensor profiles: the swept scan against the truth, the IMU against the trajectory, dropouts."""

import json

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from alte.cli import main
from alte.errors import ParameterError
from alte.sim import get_terrain, load_ground_truth, mesh_distance, simulate
from alte.sim.imu import GRAVITY, IMU_MOUNT, true_imu
from alte.sim.mission import START_NS
from alte.sim.platform import Trajectory
from alte.sim.profile import PROFILES, SensorProfile, get_profile
from alte.sim.scenario import ensure_terrain, terrain_folder

UAV = PROFILES["uav"]


@pytest.fixture(scope="module")
def nav():
    return get_terrain("sim_nav_1")


def _register_at(sim, index, times_s):
    """Scan ``index``'s points placed with the true sensor pose at ``times_s`` (s from start)."""
    traj = Trajectory(get_terrain("sim_nav_1").spec.platform, sim.duration_s)
    pos, rot = traj.pose(np.atleast_1d(times_s))
    mount = sim.mount
    sensor_pos = pos + rot.apply(mount.translation)
    sensor_rot = rot * mount.rotation
    pts = sim.scans[index]
    if len(sensor_pos) == 1:
        return sensor_rot.apply(pts) + sensor_pos
    return np.einsum("nij,nj->ni", sensor_rot.as_matrix(), pts) + sensor_pos


def test_thesis_profile_is_the_instantaneous_scan(nav):
    sim = simulate(nav, frames=2)
    assert sim.times is None and sim.imu is None and sim.profile.instantaneous
    assert not UAV.instantaneous


def test_swept_points_lie_on_the_mesh_only_from_their_own_instant(nav):
    """Each firing is cast from the pose at its instant: placing every point with the
    true pose at stamp + time puts it on the mesh (range noise only); placing the whole
    scan with the pose at its stamp does not (the vehicle flies 5 m/s)."""
    sim = simulate(nav, frames=3, profile=UAV.replace(dropout=False))
    scene = nav.scene
    k = 1  # a scan in cruise
    times = sim.times[k]
    assert times.shape == (len(sim.scans[k]),)
    assert times.min() >= 0.0375 - 1e-9 and times.max() < 0.0625 + 1e-9  # the 90 deg window
    stamp_s = (sim.stamps[k] - START_NS) / 1e9
    own = mesh_distance(_register_at(sim, k, stamp_s + times), scene)
    at_stamp = mesh_distance(_register_at(sim, k, stamp_s), scene)
    assert own.mean() < 0.03 and np.percentile(own, 99) < 0.12  # sigma 3 cm, clipped at 4
    assert at_stamp.mean() > 3 * own.mean()


def test_the_thesis_noise_is_the_same_under_every_profile(nav):
    """Dropouts draw from their own stream: with the sweep off, the uav profile's points
    are a subset of the thesis' points, bit for bit."""
    thesis = simulate(nav, frames=2)
    drop = simulate(nav, frames=2, profile=SensorProfile(dropout=True))
    for a, b in zip(thesis.scans, drop.scans, strict=True):
        assert 0 < len(b) < len(a)
        rows = {tuple(r) for r in a}
        assert all(tuple(r) in rows for r in b)
    assert drop.counts["dropout"] == sum(map(len, thesis.scans)) - sum(map(len, drop.scans))


def test_dropouts_take_dark_and_far_grazing_returns(nav):
    sim = simulate(nav, frames=2)
    drop = simulate(nav, frames=2, profile=SensorProfile(dropout=True))
    near = [np.linalg.norm(s, axis=1) for s in sim.scans]
    kept = [np.linalg.norm(s, axis=1) for s in drop.scans]
    share_far = np.mean([np.mean(r > 40) for r in near])
    assert np.mean([np.mean(r > 40) for r in kept]) < share_far  # far ground fades first


def test_mixed_pixels_put_points_between_surfaces(nav):
    plain = simulate(nav, frames=2)
    mixed = simulate(nav, frames=2, profile=SensorProfile(mixed_pixels=True))
    scene = nav.scene

    def far_share(sim):
        pts = _register_at(sim, 0, (sim.stamps[0] - START_NS) / 1e9)
        return np.mean(mesh_distance(pts, scene) > 0.2)

    assert far_share(mixed) > far_share(plain)


def test_noise_free_imu_retraces_the_trajectory(nav):
    """Integrating the noise-free samples (midpoint attitude, second-order position)
    returns the trajectory's own attitude and position: the IMU is consistent with it."""
    traj = Trajectory(nav.spec.platform, 20.0)
    rate, dt = 200.0, 1 / 200.0
    t = np.arange(1.0, 15.0, dt)
    gyro, accel = true_imu(traj, t, rate)
    attitude = traj.pose(np.array([t[0] - dt / 2]))[1][0]
    for w in gyro:
        attitude = attitude * Rotation.from_rotvec(w * dt)
    end = traj.pose(np.array([t[-1] + dt / 2]))[1][0]
    assert np.degrees((attitude.inv() * end).magnitude()) < 1e-4
    pos, rot = traj.pose(t)
    imu_pos = pos + rot.apply(IMU_MOUNT.translation)
    world = rot.apply(accel) - [0.0, 0.0, GRAVITY]
    track = [imu_pos[0], imu_pos[1]]
    for a in world[1:-1]:
        track.append(2 * track[-1] - track[-2] + a * dt * dt)
    assert np.abs(np.array(track) - imu_pos).max() < 1e-3


def test_imu_noise_has_the_stated_figures(nav):
    profile = SensorProfile(imu_hz=200.0, gyro_walk=0.0, gyro_bias=0.0, accel_walk=0.0,
                            accel_bias=0.0)
    sim = simulate(nav, frames=1, profile=profile)
    imu = sim.imu
    traj = Trajectory(nav.spec.platform, sim.duration_s)
    gyro, accel = true_imu(traj, (imu.stamps - START_NS) / 1e9, 200.0)
    g_sigma = np.std(imu.angular_velocity - gyro)
    a_sigma = np.std(imu.linear_acceleration - accel)
    assert g_sigma == pytest.approx(profile.gyro_noise * np.sqrt(200.0), rel=0.05)
    assert a_sigma == pytest.approx(profile.accel_noise * np.sqrt(200.0), rel=0.05)
    walk = simulate(nav, frames=1, profile=UAV).imu
    steps = np.diff(walk.gyro_bias, axis=0)
    assert np.std(steps) == pytest.approx(UAV.gyro_walk / np.sqrt(200.0), rel=0.05)


def test_the_uav_imu_log_begins_before_the_first_scan_with_the_vehicle_still(nav):
    quiet = UAV.replace(gyro_noise=0.0, gyro_walk=0.0, gyro_bias=0.0, accel_noise=0.0,
                        accel_walk=0.0, accel_bias=0.0, dropout=False)
    sim = simulate(nav, frames=1, profile=quiet)
    imu = sim.imu
    assert imu.stamps[0] == START_NS - 2_000_000_000 and UAV.imu_lead == 2.0
    assert (imu.stamps < START_NS).sum() == 400
    before = imu.stamps < START_NS - 50_000_000  # the vehicle tilts as it sets off at 0 s
    assert np.abs(imu.angular_velocity[before]).max() < 1e-9
    force = imu.linear_acceleration[before]
    assert np.abs(force - force[0]).max() < 1e-9
    assert np.linalg.norm(force[0]) == pytest.approx(GRAVITY)
    assert sim.stamps[0] >= START_NS


def test_uav_terrain_folder_bag_and_scenario(tmp_path):
    folder = ensure_terrain("sim_lan_1", tmp_path, frames=3, profile=UAV)
    assert folder == terrain_folder(tmp_path, "sim_lan_1", 3, 0, UAV)
    assert folder.name == "sim_lan_1-uav-3f"
    meta = json.loads((folder / "scenario.json").read_text())
    assert meta["sensor_profile"]["name"] == "uav" and meta["sensor_profile"]["sweep"]
    assert meta["imu_topic"] == "/imu" and meta["point_time_field"] == "time"
    assert meta["counts"]["imu"] > 0 and meta["counts"]["dropout"] > 0
    thesis = ensure_terrain("sim_lan_1", tmp_path, frames=3)
    assert thesis.name == "sim_lan_1-3f"
    assert json.loads((thesis / "scenario.json").read_text())["imu_topic"] is None
    truth = load_ground_truth(folder)
    assert len(truth.triangles) == len(get_terrain("sim_lan_1").scene.triangles)


def test_profile_errors_name_the_flag(tmp_path, capsys):
    with pytest.raises(ParameterError, match="sensor profile: name='lidar' unknown; "
                                             "valid: thesis, uav"):
        get_profile("lidar")
    with pytest.raises(ParameterError, match=r"unknown parameter.*imu_rate"):
        get_profile("uav", {"imu_rate": "100"})
    code = main(["simulate", "sim_lan_1", "--out", str(tmp_path), "--frames", "1",
                 "--sensor-set", "imu_hz=-5"])
    err = capsys.readouterr().err
    assert code == 2 and "--sensor-set: sensor profile: imu_hz=-5.0 out of range" in err
    code = main(["simulate", "sim_lan_1", "--out", str(tmp_path), "--frames", "1",
                 "--sensor-set", "dropout"])
    assert code == 2 and "--sensor-set 'dropout': expected KEY=VALUE" in capsys.readouterr().err
