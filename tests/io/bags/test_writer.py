"""Tests for alte.io.bags.writer: round trips through read_frames, determinism, atomicity."""

from __future__ import annotations

import hashlib
from pathlib import Path

import numpy as np
import pytest
from rosbags.highlevel import AnyReader
from scipy.spatial.transform import Rotation

from alte.errors import AlteError, BagError, ParameterError
from alte.io.bags.bag import read_frames
from alte.io.bags.writer import BagSettings, write_bag, write_frames
from alte.types import Frame, thesis_mount

NS = 1_000_000_000


def make_frames(n=5, points=40, seed=3):
    rng = np.random.default_rng(seed)
    frames = []
    for k in range(n):
        quat = Rotation.from_euler("zyx", [0.3 * k, 0.05 * k, -0.02 * k]).as_quat()
        frames.append(Frame(20 * NS + k * NS // 10 + 7, rng.uniform(-8, 8, (points, 3)),
                            np.array([0.5 * k, -0.1 * k, 2.0]), quat))
    return frames


def digest(folder: Path) -> dict[str, str]:
    return {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in sorted(folder.iterdir())}


@pytest.mark.parametrize("storage", ["sqlite3", "mcap"])
def test_round_trip_float64_is_exact(tmp_path, storage):
    frames = make_frames()
    bag = write_frames(tmp_path / "bag", frames, thesis_mount(), BagSettings(storage=storage),
                       dtype=np.float64)
    fs = read_frames(bag)
    assert fs.frames == frames
    np.testing.assert_allclose(fs.mount.translation, thesis_mount().translation)
    np.testing.assert_allclose(fs.mount.quaternion, thesis_mount().quaternion, atol=1e-15)
    assert fs.counts.frames == 5 and fs.notes == []


def test_round_trip_float32_within_1e6(tmp_path):
    frames = make_frames()
    fs = read_frames(write_frames(tmp_path / "bag", frames, thesis_mount()))
    for got, want in zip(fs.frames, frames, strict=True):
        assert got.stamp == want.stamp
        assert np.abs(got.points - want.points).max() < 1e-6
        assert np.array_equal(got.position, want.position)
        assert np.array_equal(got.quaternion, want.quaternion)


@pytest.mark.parametrize("storage", ["sqlite3", "mcap"])
def test_same_input_gives_identical_bytes(tmp_path, storage):
    frames = make_frames()
    settings = BagSettings(storage=storage)
    first = digest(write_frames(tmp_path / "a" / "bag", frames, thesis_mount(), settings))
    second = digest(write_frames(tmp_path / "b" / "bag", frames, thesis_mount(), settings))
    assert first == second and len(first) == 2
    frames[2].points[0, 0] += 1.0
    third = digest(write_frames(tmp_path / "c" / "bag", frames, thesis_mount(), settings))
    assert third != first


def test_poses_at_their_own_rate(tmp_path):
    stamps = 20 * NS + np.arange(0, 51) * (NS // 100)  # 100 Hz motion capture
    t = (stamps - 20 * NS) / NS
    pos = np.column_stack([3.0 * t, 0 * t, 1 + 0 * t])
    quat = Rotation.from_euler("z", 2.0 * t[:, None]).as_quat()
    clouds = [(20 * NS + k * NS // 10 + NS // 200, np.ones((5, 3)) * k) for k in range(5)]
    bag = write_bag(tmp_path / "bag", clouds, stamps, pos, quat, None, BagSettings(storage="mcap"))
    with AnyReader([bag]) as reader:
        log = [t for _, t, _ in reader.messages()]
        assert reader.topics["/pose"].msgcount == 51 and "/tf_static" not in reader.topics
    assert log == sorted(log)
    fs = read_frames(bag)
    for k, frame in enumerate(fs.frames):
        ts = 0.1 * k + 0.005
        np.testing.assert_allclose(frame.position, [3.0 * ts, 0, 1], atol=1e-12)
        assert frame.rotation.approx_equal(Rotation.from_euler("z", 2.0 * ts), atol=1e-12)
        assert frame.pose_offset_s == pytest.approx(0.005)
        assert frame.angular_rate == pytest.approx(2.0)
    assert "identity mount" in fs.notes[0]


def test_refuses_to_overwrite(tmp_path):
    frames = make_frames(2)
    bag = write_frames(tmp_path / "bag", frames, None)
    before = digest(bag)
    with pytest.raises(AlteError, match=r"bag already exists"):
        write_frames(tmp_path / "bag", make_frames(3), None)
    assert digest(bag) == before
    write_frames(tmp_path / "bag", make_frames(3), None, BagSettings(overwrite=True))
    assert len(read_frames(bag)) == 3
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bag"]


def test_failed_write_leaves_nothing(tmp_path):
    def clouds():
        yield 20 * NS, np.ones((3, 3))
        yield 20 * NS + 1, np.ones((3, 2))

    with pytest.raises(BagError, match=r"frame 'velodyne' must have shape \(N, 3\)"):
        write_bag(tmp_path / "bag", clouds(), [20 * NS], [[0, 0, 0]], [[0, 0, 0, 1]])
    assert list(tmp_path.iterdir()) == []


def test_argument_errors(tmp_path):
    with pytest.raises(ParameterError, match=r"storage='zip'"):
        write_frames(tmp_path / "b", make_frames(1), None, BagSettings(storage="zip"))
    with pytest.raises(BagError, match=r"poses: 2 stamps but 1 positions"):
        write_bag(tmp_path / "b", [], [1, 2], [[0, 0, 0]], [[0, 0, 0, 1]] * 2)
    with pytest.raises(BagError, match=r"poses: positions and quaternions must be finite"):
        write_bag(tmp_path / "b", [], [1], [[0, 0, np.nan]], [[0, 0, 0, 1]])
    with pytest.raises(BagError, match=r"no frames to write"):
        write_frames(tmp_path / "b", [], None)
