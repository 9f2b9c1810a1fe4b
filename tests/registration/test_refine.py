"""Pose refinement: it fixes late poses on a simulated mission without moving good ones, on
the simulator and on both real sequences, applies a correction only on evidence, and its
map is updated incrementally."""

from __future__ import annotations

from itertools import islice

import numpy as np
import pytest

from alte.io.bags.bag import FrameStream
from alte.paths import realdata_dir
from alte.registration.odometry import OdometrySettings, PoseCounts, pose_matrix, refine_frames
from alte.registration.refalign import align
from alte.registration.refmap import DenseMap
from alte.sim import get_terrain, simulate, true_poses, write_scenario
from alte.types import Frame, Mount

#: The first scans of exp_nav_2: the cart swings fast around scans 20-40, where the
#: recorded poses run 80 ms late (up to 12 deg off in yaw). 40 scans fail on what 120
#: did (the turn before the shift skipped, corrected scans fed back into the map) at a
#: third of the CPU time.
SCANS = 40


def _errors(frames: list[Frame], positions: np.ndarray, quats: np.ndarray,
            ) -> tuple[np.ndarray, np.ndarray]:
    """Position (m) and rotation (deg) error of each frame's body pose against the truth."""
    from scipy.spatial.transform import Rotation

    metres = np.linalg.norm(np.array([f.position for f in frames]) - positions, axis=1)
    turned = Rotation.from_quat([f.quaternion for f in frames]).inv() * Rotation.from_quat(quats)
    return metres, np.degrees(turned.magnitude())


@pytest.fixture(scope="module")
def desynchronised(tmp_path_factory: pytest.TempPathFactory,
                   ) -> tuple[list[Frame], Mount, np.ndarray, np.ndarray]:
    """The first :data:`SCANS` scans of exp_nav_2 with their recorded (late) poses, and the
    true body poses."""
    terrain = get_terrain("exp_nav_2")
    folder = write_scenario(tmp_path_factory.mktemp("refine") / "exp_nav_2", terrain,
                            simulate(terrain), seed=0, frames=None)
    stream = FrameStream(folder / "bag")  # the first SCANS scans only are read
    frames = list(islice(stream, SCANS))
    truth = true_poses(terrain)
    assert np.array_equal([f.stamp for f in frames], truth.stamps[:SCANS])
    return frames, stream.mount, truth.positions[:SCANS], truth.quaternions[:SCANS]


def test_refine_turns_late_poses_back_and_keeps_positions(desynchronised) -> None:
    """Refined rotations are much closer to the truth than the late recorded ones, the
    worst scan included (alignment turns a scan before it shifts it: a full alignment
    alone left the worst 0.66x off, the mean 0.84x and the positions 10 cm worse;
    measured 0.57x the recorded mean error and 0.53x the worst; over 120 scans 0.62x and
    0.47x on one machine, 0.65x and 0.48x on an AVX-512 one, whose simulated scans differ
    in their last bits (tests/README.md, reference results) and so in which scans the
    refinement corrects; refining nothing reads 1.0x), and the positions stay within
    6.5 cm of the recorded ones' error on average (measured +5.0 cm; over 120 scans
    +2.5 cm, the map of more scans: scan 13, 0.8 deg late, gains 20 % and is kept under
    the default ``min_gain`` of 30 %, and the map it is averaged into carries its error;
    at 20 % it is corrected, but accurate real scans gain up to 18 %:
    docs/results/poses.md). Corrected scans only extend the map; fed back, their errors
    let the map drift (0.79x the mean, 0.77x the worst, +7.9 cm). The first five scans,
    aligned to a map of the first scan alone, are left out of the positions."""
    frames, mount, positions, quats = desynchronised
    counts = PoseCounts()
    out = list(refine_frames(frames, mount, counts=counts, params=OdometrySettings()))
    rec_m, rec_deg = _errors(frames, positions, quats)
    ref_m, ref_deg = _errors(out, positions, quats)
    assert rec_deg.max() > 8.0  # the late poses are far off
    assert ref_deg.mean() < 0.7 * rec_deg.mean() and ref_deg.max() < 0.6 * rec_deg.max()
    settled = slice(6, None)  # scans 1-5 meet a map of one scan (docs/results/poses.md)
    assert ref_m[settled].mean() < rec_m[settled].mean() + 0.065
    assert counts.frames == SCANS and counts.corrected > SCANS // 2
    assert len(counts.scans) == SCANS and {"free", "constraint"} <= set(counts.scans[1])


def test_alignment_moves_only_along_constrained_directions() -> None:
    """A scan of a floor and one wall constrains height, tilt and the distance to the wall
    but not the slide along it: from a guess off in every direction, the alignment fixes
    what the scan constrains and leaves the slide as guessed."""
    rng = np.random.default_rng(1)
    floor = np.column_stack([rng.uniform(-6, 6, (6000, 2)), np.zeros(6000)])
    wall = np.column_stack([rng.uniform(-6, 6, 3000), np.full(3000, 3.0),
                            rng.uniform(0, 3, 3000)])
    scene = np.vstack([floor, wall]) - [0.0, 0.0, 1.0]
    local = DenseMap(0.1, 20.0, 1, 1)
    local.add(scene, np.eye(4))
    guess = np.eye(4)
    guess[:3, 3] = [0.15, 0.08, 0.05]
    found = align(local, local.source(scene), guess, length=3.0, ratio=0.002)
    assert found.free >= 1  # the slide along the wall (x) and the yaw about the wall normal
    assert abs(found.pose[1, 3]) < 0.01 and abs(found.pose[2, 3]) < 0.01
    assert found.pose[0, 3] == pytest.approx(0.15, abs=0.01)


def test_map_updates_only_what_is_new() -> None:
    """The second update appends the new cells only and re-estimates normals near them; a
    corrected scan adds cells but does not move the ones held, a confirmed one does."""
    rng = np.random.default_rng(2)
    floor = np.column_stack([rng.uniform(0, 4, (4000, 2)), np.zeros(4000)])
    local = DenseMap(0.2, 50.0, 1, 1)
    local.add(floor, np.eye(4))
    held = local.points.copy()
    shifted = np.eye(4)
    shifted[:3, 3] = [2.0, 0.0, 0.0]
    local.add(floor, shifted, confirmed=False)
    assert np.array_equal(local.points[:len(held)], held)
    assert len(local.points) > len(held) and np.all(local.points[len(held):, 0] >= 3.8)
    assert np.allclose(np.abs(local.normals[:, 2]), 1.0, atol=1e-6)
    local.add(floor, shifted, confirmed=True)
    assert not np.array_equal(local.points[:len(held)], held)


REALDATA = realdata_dir()


@pytest.mark.realdata
@pytest.mark.parametrize("sequence", ["balm_seq", "balm_seq2"])
def test_refine_leaves_accurate_real_poses_alone(sequence: str) -> None:
    """On both real sequences (accurate reference poses) refinement keeps every recorded
    pose of the first 12 scans (no alignment removes enough of the scan's own residual
    cost) and places them as recorded."""
    bag = REALDATA / sequence / "bag"
    if not bag.exists():
        pytest.skip(f"../shared/realdata/{sequence} absent")
    stream = FrameStream(bag)  # the first 12 scans only are read
    frames = list(islice(stream, 12))
    counts = PoseCounts()
    out = list(refine_frames(frames, stream.mount, counts=counts, params=OdometrySettings()))
    assert counts.corrected == 0 and counts.kept == {"first": 1, "no_gain": 11}
    for mine, theirs in zip(out, frames, strict=True):
        np.testing.assert_allclose(pose_matrix(mine.position, mine.quaternion),
                                   pose_matrix(theirs.position, theirs.quaternion), atol=1e-9)
    gains = [float(str(s["gain"])) for s in counts.scans[1:]]
    assert max(gains) < OdometrySettings().min_gain


def _room(rng: np.random.Generator, noise: float) -> np.ndarray:
    """A 8 x 8 x 2.5 m room (floor, four walls) seen from its centre, 1 m above the
    floor, with ``noise`` m of range noise: every direction constrained."""
    floor = np.column_stack([rng.uniform(-4, 4, (6000, 2)), np.full(6000, -1.0)])
    along = rng.uniform(-4, 4, 1500)
    up = rng.uniform(-1, 1.5, 1500)
    walls = [np.column_stack(c) for c in ((np.full(1500, 4.0), along, up),
                                          (np.full(1500, -4.0), along, up),
                                          (along, np.full(1500, 4.0), up),
                                          (along, np.full(1500, -3.0), up))]
    scene = np.vstack([floor, *walls])
    return scene * (1 + noise * rng.standard_normal((len(scene), 1))
                    / np.linalg.norm(scene, axis=1, keepdims=True))


def test_a_correction_at_the_noise_level_is_kept_out_a_real_one_is_applied() -> None:
    """Scans of a room with 1 cm range noise: one at its exact pose, whose best alignment
    moves it by the noise and removes a few per cent of its cost, keeps its pose
    (``no_gain``); one recorded 10 cm and 3 deg off is brought back, the correction
    removing most of its cost, unless more information along it is asked for than the
    room gives (``unobserved``)."""
    from scipy.spatial.transform import Rotation

    rng = np.random.default_rng(4)
    still = (np.zeros(3), np.array([0.0, 0.0, 0.0, 1.0]))
    off = (np.array([0.08, -0.06, 0.0]), Rotation.from_euler("z", 3, degrees=True).as_quat())
    frames = [Frame(k, _room(rng, 0.01), *pose)
              for k, pose in enumerate([still, still, still, off])]
    counts = PoseCounts()
    out = list(refine_frames(frames, Mount(), counts=counts,
                             params=OdometrySettings(voxel=0.1, rebuild=1)))
    reasons = [s["reason"] for s in counts.scans]
    assert reasons[:3] == ["first", "no_gain", "no_gain"] and reasons[3] == ""
    assert np.allclose(out[1].position, 0.0) and np.allclose(out[2].position, 0.0)
    assert np.linalg.norm(out[3].position) < 0.01
    assert float(str(counts.scans[3]["gain"])) > 0.8 > float(str(counts.scans[1]["gain"]))
    # asked for more information along the correction than the room gives, it is kept
    seen = float(str(counts.scans[3]["information"]))
    strict = PoseCounts()
    out = list(refine_frames(frames, Mount(), counts=strict,
                             params=OdometrySettings(voxel=0.1, rebuild=1,
                                                   min_information=min(2 * seen, 1.0))))
    assert strict.kept.get("unobserved") == 1 and np.allclose(out[3].position, [0.08, -0.06, 0])


def test_refine_streams(desynchronised) -> None:
    """Frames come out one by one as they go in (a generator over a generator), each
    with a decision."""
    frames, mount, _, _ = desynchronised
    counts = PoseCounts()
    stream = refine_frames(iter(frames[:12]), mount, counts=counts, params=OdometrySettings())
    first = next(stream)
    assert first.stamp == frames[0].stamp and counts.frames == 1
    rest = list(stream)
    assert len(rest) == 11 and len(counts.scans) == 12

