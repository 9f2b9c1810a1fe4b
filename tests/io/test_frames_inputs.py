"""What real bags bring: /tf_static chains, a pose file instead of a topic, per-point time."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from alte.errors import ParameterError, TopicError
from alte.io.bags.bag import ReadSettings, read_frames
from alte.io.bags.pointcloud2 import encode_pointcloud2
from alte.io.poses.tum import write_tum


def _chain(ros, links: list[tuple[str, str, tuple, tuple]]) -> list:
    stamp = 10 * ros.NS
    msgs = [m for m in ros.standard_messages(2) if m[0] != "/tf_static"]
    return [("/tf_static", ros.TF, stamp, ros.tf_msg(stamp, links)), *msgs]


def test_tf_static_chain_composes_the_mount(ros, tmp_path: Path) -> None:
    half = Rotation.from_euler("z", 90, degrees=True)
    links = [("base_link", "lidar_mount", (1.0, 0.0, 0.0), tuple(half.as_quat())),
             ("lidar_mount", "velodyne", (0.0, 2.0, 0.0), (0.0, 0.0, 0.0, 1.0)),
             ("base_link", "imu", (5.0, 5.0, 5.0), (0.0, 0.0, 0.0, 1.0))]
    fs = read_frames(ros.write_ros2(tmp_path / "bag", _chain(ros, links)))
    # velodyne in base_link: the mount's turn applied to (0, 2, 0), plus (1, 0, 0)
    assert np.allclose(fs.mount.translation, [-1.0, 0.0, 0.0], atol=1e-9)
    assert np.allclose(fs.mount.rotation.as_matrix(), half.as_matrix(), atol=1e-9)


def test_tf_static_cycle_is_an_error(ros, tmp_path: Path) -> None:
    links = [("a", "velodyne", (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0)),
             ("velodyne", "a", (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))]
    with pytest.raises(TopicError, match=r"/tf_static has a cycle: velodyne -> a -> velodyne"):
        read_frames(ros.write_ros2(tmp_path / "bag", _chain(ros, links)))


def test_pose_file_replaces_the_pose_topic(ros, tmp_path: Path) -> None:
    msgs = [m for m in ros.standard_messages(2) if m[0] != "/pose"]
    bag = ros.write_ros2(tmp_path / "bag", msgs)
    stamps = 10 * ros.NS + np.arange(0, 21) * (ros.NS // 100)
    pos, quat = ros.trajectory(stamps)
    tum = write_tum(tmp_path / "poses.txt", stamps, pos, quat)
    fs = read_frames(bag, ReadSettings(pose_file=tum))
    assert fs.pose_topic == str(tum) and len(fs) == 2
    expect, _ = ros.trajectory(np.array([fs.frames[1].stamp]))
    assert np.allclose(fs.frames[1].position, expect[0], atol=1e-6)
    with pytest.raises(ParameterError, match="read: pose_file and pose_topic exclude each other"):
        read_frames(bag, ReadSettings(pose_file=tum, pose_topic="/points"))


def test_per_point_time_reaches_the_frame(ros, tmp_path: Path) -> None:
    msgs = [m for m in ros.standard_messages(2) if m[0] != "/points"]
    for k, (stamp, pts) in enumerate(ros.scans(2)):
        sweep = np.linspace(0.0, 0.1, len(pts))
        cloud = encode_pointcloud2(pts, stamp, "velodyne", ros.TS,
                                   extra_fields={"t": (sweep * 1e9).astype(np.uint32)})
        msgs.append(("/points", ros.PC2, stamp + k, cloud))
    fs = read_frames(ros.write_ros2(tmp_path / "bag", sorted(msgs, key=lambda m: m[2])))
    times = fs.frames[0].times
    assert times is not None and len(times) == len(fs.frames[0].points)
    assert times[0] == pytest.approx(0.0) and times[-1] == pytest.approx(0.1)
