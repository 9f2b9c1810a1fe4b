"""Bad bags through the commands a user runs: ``alte info``, ``alte register``, ``alte map``.

Each test asserts what the user sees: exit code 2 with ONE stderr line naming the
bag, topic or sample at fault, or exit code 0 with a count of what was dropped.
Rows of tests/robustness/CATALOGUE.md point here.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

NS = 1_000_000_000
COMMANDS = ("register", "map")


def _argv(command: str, bag: Path, tmp_path: Path) -> list[object]:
    if command == "register":
        return ["register", bag, "--out", tmp_path / "cloud.ply"]
    return ["map", bag, "--mapper", "alte2d", "--json", "--export", tmp_path / "cells.npz"]


def _fails(bags, capsys, command: str, bag: Path, tmp_path: Path, *extra: object) -> str:
    """Run ``command`` on ``bag``: exit 2, one error line, no output file; return the line."""
    code, out, err = bags.run_cli(capsys, *_argv(command, bag, tmp_path), *extra)
    assert code == 2, (out, err)
    assert not (tmp_path / "cloud.ply").exists() and not (tmp_path / "cells.npz").exists()
    assert not [p for p in tmp_path.iterdir() if p.name.endswith(".part")]
    return bags.one_line_error(err, command)


def _register(bags, capsys, bag: Path, tmp_path: Path, *extra: object) -> str:
    code, out, err = bags.run_cli(capsys, "register", bag, "--out", tmp_path / "c.ply", *extra)
    assert code == 0, err
    return out


def _bag_counts(out: str) -> dict[str, int]:
    """The ``bag: scans read 4, ...`` line of ``alte register`` as a dict."""
    line = next(row for row in out.splitlines() if row.startswith("bag: "))
    pairs = (item.rsplit(" ", 1) for item in line.removeprefix("bag: ").split(", "))
    return {name: int(value) for name, value in pairs}


# ------------------------------------------------------------------ missing / empty / truncated


@pytest.mark.parametrize("command", ["info", *COMMANDS])
def test_missing_bag(bags, capsys, tmp_path, command):
    bag = tmp_path / "nope.bag"
    line = (bags.one_line_error(bags.run_cli(capsys, "info", bag)[2], "info") if command == "info"
            else _fails(bags, capsys, command, bag, tmp_path))
    assert f"bag {bag} does not exist" in line


@pytest.mark.parametrize("command", COMMANDS)
def test_empty_bag(bags, capsys, tmp_path, command):
    bag = bags.write_ros2(tmp_path / "empty", [])
    assert f"{bag} is empty: no messages" in _fails(bags, capsys, command, bag, tmp_path)


def test_empty_bag_info_reports_no_topics(bags, capsys, tmp_path):
    bag = bags.write_ros2(tmp_path / "empty", [])
    code, out, _ = bags.run_cli(capsys, "info", bag, "--json")
    info = json.loads(out)
    assert code == 0 and info["topics"] == {} and info["cloud_topic"] is None


@pytest.mark.parametrize("storage", ["sqlite3", "mcap"])
@pytest.mark.parametrize("fraction", [0.05, 0.3, 0.6, 0.97])
def test_truncated_bag(bags, capsys, tmp_path, storage, fraction):
    bag = bags.write_ros2(tmp_path / "cut", bags.mission(8), storage)
    data = next(p for p in bag.iterdir() if p.suffix in {".db3", ".mcap"})
    blob = data.read_bytes()
    data.write_bytes(blob[: int(len(blob) * fraction)])
    for command in ("info", "register"):
        if command == "info":
            code, _, err = bags.run_cli(capsys, "info", bag)
            assert code == 2
            line = bags.one_line_error(err, "info")
        else:
            line = _fails(bags, capsys, command, bag, tmp_path)
        assert str(bag) in line
        assert "truncated" in line or "not a readable ROS bag" in line


# ------------------------------------------------------------------ topics


@pytest.mark.parametrize("command", COMMANDS)
@pytest.mark.parametrize("poses", ["recorded", "refine"])
def test_clouds_without_poses(bags, capsys, tmp_path, command, poses):
    bag = bags.write_ros2(tmp_path / "nopose", bags.mission(poses=False))
    line = _fails(bags, capsys, command, bag, tmp_path, "--poses", poses)
    assert f"--poses: {bag}: poses={poses} needs the bag's poses and it has no pose topic" in line
    assert "for /points; use poses=odometry" in line


def test_clouds_without_poses_use_odometry_and_say_so(bags, capsys, tmp_path):
    bag = bags.write_ros2(tmp_path / "nopose", bags.mission(poses=False))
    code, out, err = bags.run_cli(capsys, *_argv("map", bag, tmp_path))
    assert code == 0, err
    summary = json.loads(out)
    assert summary["pose_source"] == "odometry" and summary["frames"] == 4
    assert any("poses from LiDAR odometry" in n for n in summary["counts"]["notes"])
    assert "poses: odometry" in _register(bags, capsys, bag, tmp_path)


def test_no_pose_and_poses_exclude_each_other(bags, capsys, tmp_path):
    bag = bags.write_ros2(tmp_path / "nopose", bags.mission(poses=False))
    line = _fails(bags, capsys, "register", bag, tmp_path, "--no-pose", "--poses", "odometry")
    assert "--no-pose and --poses odometry exclude each other" in line


def test_clouds_without_poses_recover_with_no_pose(bags, capsys, tmp_path):
    bag = bags.write_ros2(tmp_path / "nopose", bags.mission(poses=False))
    out = _register(bags, capsys, bag, tmp_path, "--no-pose")
    assert _bag_counts(out)["frames"] == 4 and "wrote 160 points" in out


@pytest.mark.parametrize("command", COMMANDS)
def test_poses_without_clouds(bags, capsys, tmp_path, command):
    bag = bags.write_ros2(tmp_path / "noclouds", bags.mission(clouds=False))
    line = _fails(bags, capsys, command, bag, tmp_path)
    assert f"{bag}: no cloud topic" in line and "/pose [geometry_msgs/msg/PoseStamped]" in line


def test_info_shows_what_is_missing(bags, capsys, tmp_path):
    bag = bags.write_ros2(tmp_path / "noclouds", bags.mission(clouds=False))
    code, out, _ = bags.run_cli(capsys, "info", bag)
    assert code == 0 and "cloud:     - (0 scans)" in out and "pose:      /pose" in out


# ------------------------------------------------------------------ PointCloud2 contents


def test_nonfinite_points_are_dropped_and_counted(bags, capsys, tmp_path):
    bad = [[np.nan, 1.0, 1.0], [np.inf, 0.0, 0.0], [0.0, -np.inf, 2.0]]
    msgs = bags.mission(points=lambda k: np.vstack([bags.scan_points(k), bad]))
    bag = bags.write_ros2(tmp_path / "nan", msgs)
    out = _register(bags, capsys, bag, tmp_path)
    assert _bag_counts(out)["points nonfinite"] == 12  # 3 per scan, 4 scans
    assert "points: 160 in" in out and "wrote 160 points" in out


@pytest.mark.parametrize("command", COMMANDS)
def test_all_points_nonfinite(bags, capsys, tmp_path, command):
    msgs = bags.mission(points=lambda k: np.full((5, 3), np.nan))
    bag = bags.write_ros2(tmp_path / "allnan", msgs)
    line = _fails(bags, capsys, command, bag, tmp_path)
    assert f"{bag}:/points: all 4 scans have no usable points" in line


def test_zero_point_scans_are_dropped_and_counted(bags, capsys, tmp_path):
    msgs = bags.mission(points=lambda k: np.empty((0, 3)) if k % 2 else bags.scan_points(k))
    bag = bags.write_ros2(tmp_path / "zero", msgs)
    counts = _bag_counts(_register(bags, capsys, bag, tmp_path))
    assert counts["scans read"] == 4 and counts["scans empty"] == 2 and counts["frames"] == 2


@pytest.mark.parametrize("command", COMMANDS)
@pytest.mark.parametrize("case", [
    (8, "point_step 8 is smaller than the 12 bytes its fields need"),
    (16, "data has 480 bytes, expected height 1 * row_step 640"),
])
def test_wrong_point_step(bags, capsys, tmp_path, command, case):
    step, message = case
    msgs = [(topic, kind, stamp, bags.cloud_msg(stamp, bags.scan_points(0), point_step=step)
             if topic == "/points" else msg) for topic, kind, stamp, msg in bags.mission()]
    bag = bags.write_ros2(tmp_path / "step", msgs)
    assert f"/points: {message}" in _fails(bags, capsys, command, bag, tmp_path)


# ------------------------------------------------------------------ stamps


def test_duplicate_and_reordered_pose_stamps_are_counted(bags, capsys, tmp_path):
    """Header stamps out of order and repeated (log times stay in order, as recorded)."""
    msgs = bags.mission()
    poses = [m for m in msgs if m[0] == "/pose"]
    swapped = {5: poses[6][3], 6: poses[5][3]}  # samples 5 and 6 swap their messages
    msgs = [(t, k, s, swapped.get(poses.index(m), msg) if t == "/pose" else msg)
            for m in msgs for t, k, s, msg in [m]]
    repeats = [("/pose", bags.POSE, 12 * NS + i, poses[10 + i][3]) for i in range(3)]
    bag = bags.write_ros2(tmp_path / "dups", msgs + repeats)
    counts = _bag_counts(_register(bags, capsys, bag, tmp_path))
    assert counts["pose duplicates"] == 3 and counts["pose reordered"] == 2
    assert counts["pose samples"] == len(poses) and counts["frames"] == 4


def test_duplicate_and_reordered_scan_stamps_are_posed_each(bags, capsys, tmp_path):
    stamps = [10 * NS + 3 * NS // 10, 10 * NS, 10 * NS, 10 * NS + NS // 10]
    bag = bags.write_ros2(tmp_path / "scans", bags.mission(scan_stamps=stamps))
    out = _register(bags, capsys, bag, tmp_path)
    counts = _bag_counts(out)
    assert counts["scans read"] == 4 and counts["frames"] == 4  # kept, each at its own stamp
    assert "wrote 160 points" in out


def test_pose_gap_drops_and_counts_scans(bags, capsys, tmp_path):
    pose_stamps = [10 * NS + k * NS // 100 for k in [*range(-2, 21), *range(80, 102)]]
    bag = bags.write_ros2(tmp_path / "gap", bags.mission(10, pose_stamps=pose_stamps))
    counts = _bag_counts(_register(bags, capsys, bag, tmp_path))
    assert counts["scans in pose gap"] == 5  # scans at 10.3 .. 10.7 s, gap 10.2 -> 10.8 s
    assert counts["frames"] == 5


def test_pose_gap_over_every_scan_is_an_error(bags, capsys, tmp_path):
    pose_stamps = [9 * NS, 12 * NS]
    bag = bags.write_ros2(tmp_path / "gap", bags.mission(pose_stamps=pose_stamps))
    line = _fails(bags, capsys, "register", bag, tmp_path)
    assert f"{bag}:/points: no scan has a pose from {bag}:/pose" in line
    assert "4 in gaps > 0.5 s" in line


@pytest.mark.parametrize("command", COMMANDS)
@pytest.mark.parametrize("case", [(NS, 1, "scan"), (1, NS, "pose")])
def test_stamps_in_seconds(bags, capsys, tmp_path, command, case):
    """A clock in seconds written as nanoseconds: a factor 1e9 between scans and poses."""
    scan_unit, pose_unit, larger = case
    scans = [(10 + k) * scan_unit for k in range(4)]
    poses = [(9 + k) * pose_unit for k in range(6)]
    bag = bags.write_ros2(tmp_path / "units", bags.mission(scan_stamps=scans, pose_stamps=poses))
    line = _fails(bags, capsys, command, bag, tmp_path)
    assert f"{bag}:/pose: {larger} stamps are ~1e+09 times larger" in line
    assert "seconds vs nanoseconds" in line


# ------------------------------------------------------------------ quaternions


@pytest.mark.parametrize("command", COMMANDS)
def test_zero_quaternion_names_the_sample(bags, capsys, tmp_path, command):
    msgs = bags.mission(quat=lambda i: (0.0, 0.0, 0.0, 0.0) if i == 5 else bags.IDENTITY)
    bag = bags.write_ros2(tmp_path / "zeroq", msgs)
    line = _fails(bags, capsys, command, bag, tmp_path)
    assert f"{bag}:/pose: sample 5 (stamp 10030000000 ns) has an unusable pose" in line


def test_non_unit_quaternions_are_normalized_with_a_warning(bags, capsys, tmp_path):
    half = np.sqrt(0.5)
    msgs = bags.mission(quat=lambda i: (0.0, 0.0, 2 * half, 2 * half))  # norm 2, yaw 90 deg
    bag = bags.write_ros2(tmp_path / "q2", msgs)
    with pytest.warns(UserWarning, match=r"/pose: 44 quaternions are not unit .*normalized"):
        out = _register(bags, capsys, bag, tmp_path)
    assert _bag_counts(out)["frames"] == 4
    from alte.io.points.pointfiles import read_points

    cloud = read_points(tmp_path / "c.ply")
    first = bags.scan_points(0).astype(np.float32).astype(np.float64)
    yaw90 = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    expected = first @ yaw90.T + [0.2, 0.0, 2.0]  # scan 0 is posed by pose sample 2
    assert np.allclose(np.sort(cloud[:40], axis=0), np.sort(expected, axis=0), atol=1e-6)


# ------------------------------------------------------------------ points beyond the range


def _far_bag(bags, tmp_path: Path) -> Path:
    far = [[0.0, 5000.0, 0.0], [0.0, 1.0e7, 0.0]]  # 5 km and 10,000 km: beyond a VLP-16's 100 m
    msgs = bags.mission(points=lambda k: np.vstack([bags.scan_points(k), far]))
    return bags.write_ros2(tmp_path / "far", msgs)


def test_far_points_dropped_by_the_control_volume(bags, capsys, tmp_path):
    out = _register(bags, capsys, _far_bag(bags, tmp_path), tmp_path, "--crop=-50,-50,-50,50,50,50")
    assert "8 (outside crop box)" in out and "wrote 160 points" in out


@pytest.mark.parametrize(("mapper", "domain"), [("quadtree", "-64,-64,128"),
                                                ("alte2d", "-64,-64,128"),
                                                ("alte3d", "-64,-64,-64,128")])
def test_far_points_outside_a_domain_are_dropped_and_counted(bags, capsys, tmp_path, mapper,
                                                              domain):
    code, out, err = bags.run_cli(capsys, "map", _far_bag(bags, tmp_path), "--mapper", mapper,
                                  f"--domain={domain}", "--json")
    assert code == 0, err
    summary = json.loads(out)
    assert summary["points_outside"] == 8 and summary["points"] == 168


def test_far_points_outside_octomaps_key_space_are_counted(bags, capsys, tmp_path):
    code, out, err = bags.run_cli(capsys, "map", _far_bag(bags, tmp_path), "--mapper", "octomap",
                                  "--json")
    assert code == 0, err
    assert json.loads(out)["points_outside"] == 4  # 10,000 km is outside, 5 km is not


def test_far_points_never_occupy_octomap_cells(bags, capsys, tmp_path):
    """Rays longer than ``max_range`` are cut and their end is not marked occupied."""
    code, _, err = bags.run_cli(capsys, "map", _far_bag(bags, tmp_path), "--mapper", "octomap",
                                "--set", "max_range=50", "--export", tmp_path / "o.npz")
    assert code == 0, err
    with np.load(tmp_path / "o.npz") as cells:
        occupied = cells["centers"][cells["occupied"]]
    assert len(occupied) > 0 and np.abs(occupied).max() < 60.0


def test_pose_topic_on_another_clock_recovers_with_odometry(bags, capsys, tmp_path):
    """Poses an hour after the scans: the error names the flags, --poses odometry maps."""
    scans = [(10 + k) * bags.NS for k in range(4)]
    poses = [(3600 + k) * bags.NS for k in range(6)]
    bag = bags.write_ros2(tmp_path / "clock", bags.mission(scan_stamps=scans, pose_stamps=poses))
    line = _fails(bags, capsys, "register", bag, tmp_path)
    assert "--poses, --pose-topic, --pose-file: " in line and "different clocks?" in line
    out = _register(bags, capsys, bag, tmp_path, "--poses", "odometry", "--odometry", "plane")
    assert "poses: odometry (point-to-plane" in out
