"""Tests for ``alte info``: text and JSON summaries of a bag written in tmp_path."""

from __future__ import annotations

import json

import numpy as np
import pytest

from alte.cli import main
from alte.io.writer import write_bag
from alte.types import thesis_mount

NS = 1_000_000_000


@pytest.fixture
def bag(tmp_path):
    clouds = [(NS + k * NS // 10, np.full((4, 3), float(k))) for k in range(3)]
    stamps = NS + np.arange(21) * NS // 100
    pos = np.zeros((21, 3))
    quat = np.tile([0.0, 0.0, 0.0, 1.0], (21, 1))
    return write_bag(tmp_path / "bag", clouds, stamps, pos, quat, thesis_mount(),
                     cloud_topic="/lidar", pose_topic="/vicon")


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

    from alte.io.pointcloud2 import encode_pointcloud2

    write_ros2(bare, [("/lidar", "sensor_msgs/msg/PointCloud2", s,
                       encode_pointcloud2(p, s, "lidar", TS)) for s, p in clouds])
    assert main(["info", str(bare), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["pose_source"].startswith("odometry")
