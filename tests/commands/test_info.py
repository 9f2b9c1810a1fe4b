"""Tests for ``alte info``: text and JSON summaries of a bag written in tmp_path."""

from __future__ import annotations

import json

import numpy as np
import pytest

from alte.cli import main
from alte.io.bags.writer import BagSettings, write_bag
from alte.types import thesis_mount

NS = 1_000_000_000


@pytest.fixture
def bag(tmp_path):
    clouds = [(NS + k * NS // 10, np.full((4, 3), float(k))) for k in range(3)]
    stamps = NS + np.arange(21) * NS // 100
    pos = np.zeros((21, 3))
    quat = np.tile([0.0, 0.0, 0.0, 1.0], (21, 1))
    return write_bag(tmp_path / "bag", clouds, stamps, pos, quat, thesis_mount(),
                     BagSettings(cloud_topic="/lidar", pose_topic="/vicon"))


def test_info_json(bag, capsys):
    assert main(["info", str(bag), "--json"]) == 0
    out = capsys.readouterr().out
    assert out.count("\n") == 1
    info = json.loads(out)
    assert info["cloud_topic"] == "/lidar" and info["pose_topic"] == "/vicon"
    assert info["frames"] == 3
    assert info["duration_s"] == pytest.approx(0.2, abs=1e-6)
    assert info["topics"]["/vicon"] == {"type": "geometry_msgs/msg/PoseStamped", "count": 21}
    assert set(info["topics"]) == {"/lidar", "/vicon", "/tf_static"}


def test_info_text(bag, capsys):
    assert main(["info", str(bag)]) == 0
    out = capsys.readouterr().out
    assert "/lidar" in out and "sensor_msgs/msg/PointCloud2" in out
    assert "cloud:     /lidar (3 scans)" in out and "pose:      /vicon" in out
    assert "mount:     0.1,0,-0.08," in out


def test_info_errors_exit_2(bag, tmp_path, capsys):
    assert main(["info", str(tmp_path / "nope")]) == 2
    assert "alte info: error: bag" in capsys.readouterr().err
    assert main(["info", str(bag), "--pose-topic", "/lidar"]) == 2
    assert "pose topic /lidar has type sensor_msgs/msg/PointCloud2" in capsys.readouterr().err


def test_info_says_which_pose_source_is_used(bag, tmp_path, capsys):
    assert main(["info", str(bag)]) == 0
    assert "poses:     recorded (/vicon)" in capsys.readouterr().out
    clouds = [(NS + k * NS // 10, np.full((4, 3), float(k))) for k in range(3)]
    bare = tmp_path / "bare"
    from support.bagtools import TS, write_ros2

    from alte.io.bags.pointcloud2 import encode_pointcloud2

    write_ros2(bare, [("/lidar", "sensor_msgs/msg/PointCloud2", s,
                       encode_pointcloud2(p, s, "lidar", TS)) for s, p in clouds])
    assert main(["info", str(bare), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["pose_source"].startswith("odometry")


def _organised_pcd(path):
    """A 4 x 2 organised binary PCD with intensity and one NaN return."""
    data = np.zeros(8, [("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("intensity", "<f4")])
    data["x"], data["y"], data["z"] = np.arange(8), np.arange(8) * 2, 1.5
    data["x"][5] = np.nan
    data["intensity"] = np.arange(8) * 10
    head = ("VERSION .7\nFIELDS x y z intensity\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\n"
            "WIDTH 4\nHEIGHT 2\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 8\nDATA binary\n")
    path.write_bytes(head.encode() + data.tobytes())
    return path


def test_info_describes_a_point_file(tmp_path, capsys):
    pcd = _organised_pcd(tmp_path / "scan.pcd")
    assert main(["info", str(pcd)]) == 0
    text = capsys.readouterr().out
    assert "format:    PCD .7, binary" in text
    assert "fields:    x F4, y F4, z F4, intensity F4" in text
    assert "points:    8 rows: 7 finite, 1 non-finite (1 with NaN)" in text
    assert "layout:    organised, 4 x 2" in text
    assert "bounds:    x 0.000 .. 7.000, y 0.000 .. 14.000, z 1.500 .. 1.500" in text
    assert "intensity    0 .. 70" in text
    assert main(["info", str(pcd), "--json"]) == 0
    about = json.loads(capsys.readouterr().out)
    assert (about["rows"], about["points"], about["nonfinite"], about["nan"]) == (8, 7, 1, 1)
    assert about["bounds"] == [[0.0, 0.0, 1.5], [7.0, 14.0, 1.5]]
    assert [f["name"] for f in about["fields"]] == ["x", "y", "z", "intensity"]
    assert (about["encoding"], about["width"], about["height"]) == ("binary", 4, 2)


def test_info_refuses_a_truncated_ascii_pcd(tmp_path, capsys):
    pcd = tmp_path / "half.pcd"
    rows = "".join(f"{k} {k} {k}\n" for k in range(5))
    pcd.write_text("VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
                   f"WIDTH 10\nHEIGHT 1\nPOINTS 10\nDATA ascii\n{rows}")
    assert main(["info", str(pcd)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert f"{pcd}: truncated ascii PCD: 5 of the 10 rows its header announces" in err


def test_info_needs_an_input_or_mappers(capsys):
    assert main(["info"]) == 2
    assert ("alte info: error: give INPUT (a bag, terrain folder or point file) or "
            "--mappers") in capsys.readouterr().err
    assert main(["info", "--mappers", "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)
    assert [r["name"] for r in rows[:4]] == ["quadtree", "octomap", "alte2d", "alte3d"]
    assert all(r["status"] == "ok" for r in rows)
