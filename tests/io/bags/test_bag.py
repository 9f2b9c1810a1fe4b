"""Tests for alte.io.bags.bag / alte.io.bags.reader on bags written with rosbags in tmp_path,
plus the real ROS 1 and raw VLP-16 recordings."""

from __future__ import annotations

import shutil

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from alte.errors import BagError, ParameterError, PoseError, TopicError
from alte.io.bags.bag import ReadSettings, read_frames
from alte.io.bags.baginfo import inspect_bag
from alte.types import Mount


def _identity(n):
    return np.zeros((n, 3)), np.tile([0.0, 0.0, 0.0, 1.0], (n, 1))


@pytest.mark.parametrize("storage", ["sqlite3", "mcap"])
def test_read_frames_interpolates_poses_and_reads_mount(ros, tmp_path, storage):
    bag = ros.write_ros2(tmp_path / "bag", ros.standard_messages(4), storage)
    fs = read_frames(bag)
    assert (fs.cloud_topic, fs.pose_topic, len(fs)) == ("/points", "/pose", 4)
    expected = ros.scans(4)
    stamps = np.array([s for s, _ in expected])
    pos, quat = ros.trajectory(stamps)
    for k, frame in enumerate(fs.frames):
        assert frame.stamp == expected[k][0]
        np.testing.assert_array_equal(frame.points, expected[k][1].astype(np.float32))
        np.testing.assert_allclose(frame.position, pos[k], atol=1e-12)
        assert Rotation.from_quat(frame.quaternion).approx_equal(Rotation.from_quat(quat[k]))
        assert frame.pose_offset_s == 0.0 and frame.angular_rate > 0.5
    np.testing.assert_allclose(fs.mount.translation, [0.1, 0.0, -0.08])
    np.testing.assert_allclose(fs.mount.quaternion, [0, 0, 0.3826834, 0.9238795], atol=1e-7)
    assert fs.counts.scans_read == 4 and fs.counts.pose_samples == 41
    assert fs.notes == []


def test_mount_argument_overrides_tf_static(ros, tmp_path):
    bag = ros.write_ros2(tmp_path / "bag", ros.standard_messages(2))
    mine = Mount.from_string("1,2,3,0,0,90")
    fs = read_frames(bag, mount=mine)
    assert fs.mount is mine and "overrides" in fs.notes[0]


def test_interpolated_pose_between_samples(ros, tmp_path):
    msgs = ros.standard_messages(2)
    msgs = [m for m in msgs if m[0] != "/pose" or (m[2] // (ros.NS // 100)) % 4 == 0]
    fs = read_frames(ros.write_ros2(tmp_path / "bag", msgs))
    stamp = fs.frames[1].stamp  # 10.1 s, between poses at 10.08 and 10.12 s
    pos, _ = ros.trajectory(np.array([stamp]))
    np.testing.assert_allclose(fs.frames[1].position, pos[0], atol=1e-3)
    assert fs.frames[1].pose_offset_s == pytest.approx(0.02)


def test_scans_outside_poses_and_in_gaps_are_dropped_and_counted(ros, tmp_path):
    msgs = [m for m in ros.standard_messages(6) if m[0] != "/pose"]
    t = ros.NS * np.array([10.1, 10.15, 10.2, 10.6, 10.65])  # gap 10.2 .. 10.6 s
    pos, quat = ros.trajectory(t)
    msgs += [("/pose", ros.POSE, int(s), ros.pose_msg(int(s), p, q))
             for s, p, q in zip(t, pos, quat, strict=True)]
    bag = ros.write_ros2(tmp_path / "bag", sorted(msgs, key=lambda m: m[2]))
    fs = read_frames(bag, ReadSettings(max_gap_s=0.3))
    assert [f.stamp for f in fs.frames] == [int(10.1 * ros.NS), int(10.2 * ros.NS)]
    c = fs.counts
    assert (c.scans_read, c.scans_outside_poses, c.scans_in_pose_gap) == (6, 1, 3)
    assert c.frames == 2


def test_no_scan_in_pose_range_is_a_clock_error(ros, tmp_path):
    msgs = [m for m in ros.standard_messages(2) if m[0] != "/pose"]
    msgs += [("/pose", ros.POSE, s, ros.pose_msg(s, (0, 0, 0), (0, 0, 0, 1)))
             for s in (500 * ros.NS, 501 * ros.NS)]
    with pytest.raises(PoseError, match=r"no scan has a pose .*\(2 outside .*different clocks"):
        read_frames(ros.write_ros2(tmp_path / "bag", msgs))


def test_pose_stamps_in_seconds_are_detected(ros, tmp_path):
    msgs = [m for m in ros.standard_messages(2) if m[0] != "/pose"]
    msgs += [("/pose", ros.POSE, s * ros.NS, ros.pose_msg(s, (0, 0, 0), (0, 0, 0, 1)))
             for s in (9, 10, 11)]  # header stamps 9..11 ns: seconds written as ns
    with pytest.raises(PoseError, match=r"scan stamps are ~1e\+09 times larger"):
        read_frames(ros.write_ros2(tmp_path / "bag", sorted(msgs, key=lambda m: m[2])))


def test_zero_header_stamp_falls_back_to_log_time(ros, tmp_path):
    msgs = [m for m in ros.standard_messages(2) if m[0] != "/points"]
    msgs.append(("/points", ros.PC2, int(10.05 * ros.NS), ros.cloud_msg(0, np.ones((3, 3)))))
    fs = read_frames(ros.write_ros2(tmp_path / "bag", sorted(msgs, key=lambda m: m[2])))
    assert [f.stamp for f in fs.frames] == [int(10.05 * ros.NS)]


def test_nonfinite_and_empty_scans(ros, tmp_path):
    msgs = [m for m in ros.standard_messages(2) if m[0] != "/points"]
    pts = np.ones((4, 3))
    pts[1, 0] = np.nan
    msgs.append(("/points", ros.PC2, 10 * ros.NS, ros.cloud_msg(10 * ros.NS, pts)))
    empty = ros.cloud_msg(int(10.1 * ros.NS), np.full((2, 3), np.inf))
    msgs.append(("/points", ros.PC2, 11 * ros.NS, empty))
    fs = read_frames(ros.write_ros2(tmp_path / "bag", msgs))
    assert len(fs) == 1 and fs.frames[0].dropped_points == 1 and len(fs.frames[0].points) == 3
    assert fs.counts.points_nonfinite == 3 and fs.counts.scans_empty == 1


def test_all_scans_unusable_is_an_error(ros, tmp_path):
    msgs = [m for m in ros.standard_messages(2) if m[0] != "/points"]
    msgs += [("/points", ros.PC2, s, ros.cloud_msg(s, np.full((2, 3), np.nan)))
             for s in (10 * ros.NS, 10 * ros.NS + ros.NS // 10)]
    with pytest.raises(BagError, match=r"/points: all 2 scans have no usable points"):
        read_frames(ros.write_ros2(tmp_path / "bag", msgs))


def test_odometry_poses(ros, tmp_path):
    msgs = [m for m in ros.standard_messages(2) if m[0] != "/pose"]
    stamps = 10 * ros.NS + np.arange(0, 21) * (ros.NS // 100)
    pos, quat = ros.trajectory(stamps)
    msgs += [("/odom", ros.ODOM, int(s), ros.odom_msg(int(s), p, q))
             for s, p, q in zip(stamps, pos, quat, strict=True)]
    fs = read_frames(ros.write_ros2(tmp_path / "bag", msgs))
    assert fs.pose_topic == "/odom" and len(fs) == 2
    np.testing.assert_allclose(fs.frames[1].position, pos[10])


def test_tf_poses_pick_the_body_leaf(ros, tmp_path):
    msgs = [m for m in ros.standard_messages(2) if m[0] not in ("/pose", "/tf_static")]
    stamps = 10 * ros.NS + np.arange(0, 21) * (ros.NS // 100)
    pos, quat = ros.trajectory(stamps)
    msgs += [("/tf", ros.TF, int(s), ros.tf_msg(int(s), [
        ("map", "odom", (100, 0, 0), (0, 0, 0, 1)), ("odom", "base_link", p, q),
        ("base_link", "velodyne", (9, 9, 9), (0, 0, 0, 1))]))
        for s, p, q in zip(stamps, pos, quat, strict=True)]
    fs = read_frames(ros.write_ros2(tmp_path / "bag", msgs))
    assert fs.pose_topic == "/tf" and len(fs) == 2
    np.testing.assert_allclose(fs.frames[1].position, pos[10])
    assert np.array_equal(fs.mount.translation, np.zeros(3)) and "identity mount" in fs.notes[0]
    fs = read_frames(ros.write_ros2(tmp_path / "bag2", msgs), ReadSettings(body_frame="odom"))
    np.testing.assert_allclose(fs.frames[1].position, [100, 0, 0])


def test_ros1_bag_with_poses(ros, tmp_path):
    bag = ros.write_ros1(tmp_path / "small.bag", ros.standard_messages(3))
    fs = read_frames(bag)
    assert len(fs) == 3 and fs.pose_topic == "/pose"
    np.testing.assert_allclose(fs.mount.translation, [0.1, 0.0, -0.08])
    assert inspect_bag(bag).topics["/points"] == (ros.PC2, 3)


def test_topic_ambiguity_absence_and_bad_overrides(ros, tmp_path):
    msgs = ros.standard_messages(2)
    two = msgs + [("/other", ros.PC2, m[2], m[3]) for m in msgs if m[0] == "/points"]
    bag = ros.write_ros2(tmp_path / "two", two)
    listing = r"topics in the bag: /other \[sensor_msgs/msg/PointCloud2\], /points"
    with pytest.raises(TopicError, match=rf"several cloud topics \(/other, /points\).*{listing}"):
        read_frames(bag)
    assert len(read_frames(bag, ReadSettings(cloud_topic="/other"))) == 2
    with pytest.raises(TopicError, match=r"cloud topic /nope is not in the bag; topics in"):
        read_frames(bag, ReadSettings(cloud_topic="/nope"))
    with pytest.raises(TopicError, match=r"pose topic /points has type sensor_msgs/msg/Point"):
        read_frames(bag, ReadSettings(cloud_topic="/points", pose_topic="/points"))
    poses = msgs + [("/pose2", ros.POSE, m[2], m[3]) for m in msgs if m[0] == "/pose"]
    with pytest.raises(TopicError, match=r"several pose topics \(/pose, /pose2\)"):
        read_frames(ros.write_ros2(tmp_path / "poses", poses))
    only_pose = [m for m in msgs if m[0] == "/pose"]
    with pytest.raises(TopicError, match=r"no cloud topic .*topics in the bag: /pose \["):
        read_frames(ros.write_ros2(tmp_path / "nocloud", only_pose))


def test_missing_pose_topic(ros, tmp_path):
    msgs = [m for m in ros.standard_messages(2) if m[0] != "/pose"]
    bag = ros.write_ros2(tmp_path / "bag", msgs)
    with pytest.raises(TopicError, match=r"no pose topic .*allow_no_pose.*/points \["):
        read_frames(bag)
    fs = read_frames(bag, ReadSettings(allow_no_pose=True))
    assert len(fs) == 2 and np.array_equal(fs.frames[0].quaternion, [0, 0, 0, 1])
    assert fs.pose_topic is None and "identity pose" in fs.notes[-1]


def test_progress_bar_runs(ros, tmp_path, capsys):
    bag = ros.write_ros2(tmp_path / "bag", ros.standard_messages(2))
    assert len(read_frames(bag, ReadSettings(progress=True))) == 2
    assert "/points" in capsys.readouterr().err


def test_missing_and_not_a_bag(tmp_path):
    with pytest.raises(BagError, match=r"bag .*missing.bag does not exist"):
        read_frames(tmp_path / "missing.bag")
    junk = tmp_path / "junk.bag"
    junk.write_bytes(b"not a bag" * 50)
    with pytest.raises(BagError, match=r"junk.bag is not a readable ROS bag"):
        read_frames(junk)
    (tmp_path / "folder").mkdir()
    with pytest.raises(BagError, match=r"folder is not a readable ROS bag"):
        inspect_bag(tmp_path / "folder")


def test_empty_bag(ros, tmp_path):
    bag = ros.write_ros2(tmp_path / "empty", [])
    with pytest.raises(BagError, match=r"empty.* is empty: no messages"):
        read_frames(bag)
    assert inspect_bag(bag).topics == {}


def test_bad_max_gap(ros, tmp_path):
    """Read options are checked before the bag is opened (``tmp_path`` is none)."""
    with pytest.raises(ParameterError, match=r"read: max_gap_s=0.0 out of range \(max_gap_s > 0\)"):
        read_frames(tmp_path, ReadSettings(max_gap_s=0))
    with pytest.raises(ParameterError, match=r"read: return_mode='first' out of range "
                                             r"\(strongest\|last\|dual\)"):
        read_frames(tmp_path, ReadSettings(return_mode="first"))


@pytest.mark.parametrize("storage", ["sqlite3", "mcap"])
@pytest.mark.parametrize("fraction", [0.0, 0.05, 0.5, 0.9, 0.995])
def test_truncated_bag(ros, tmp_path, storage, fraction):
    bag = ros.write_ros2(tmp_path / "bag", ros.standard_messages(4), storage)
    data_file = next(p for p in bag.iterdir() if p.name != "metadata.yaml")
    data = data_file.read_bytes()
    data_file.write_bytes(data[: int(len(data) * fraction)])
    with pytest.raises(BagError, match=rf"{data_file.name}|bag is not a readable"):
        read_frames(bag)


def test_truncated_ros1_bag(ros, tmp_path):
    bag = ros.write_ros1(tmp_path / "small.bag", ros.standard_messages(3))
    data = bag.read_bytes()
    for cut in (10, len(data) // 2, len(data) - 20):
        bag.write_bytes(data[:cut])
        with pytest.raises(BagError, match=r"small.bag is not a readable ROS bag"):
            read_frames(bag)


def test_inspect_bag(ros, tmp_path):
    bag = ros.write_ros2(tmp_path / "bag", ros.standard_messages(4), "mcap")
    info = inspect_bag(bag)
    assert info.topics == {"/points": (ros.PC2, 4), "/pose": (ros.POSE, 41),
                           "/tf_static": (ros.TF, 1)}
    assert (info.cloud_topic, info.pose_topic, info.frames) == ("/points", "/pose", 4)
    assert info.duration_s == pytest.approx(0.4, abs=1e-6)
    d = info.to_dict()
    assert d["topics"]["/pose"] == {"type": ros.POSE, "count": 41}
    np.testing.assert_allclose(d["mount"]["translation"], [0.1, 0.0, -0.08])


def test_inspect_reports_ambiguity_instead_of_raising(ros, tmp_path):
    msgs = ros.standard_messages(2)
    msgs += [("/pose2", ros.POSE, m[2], m[3]) for m in msgs if m[0] == "/pose"]
    info = inspect_bag(ros.write_ros2(tmp_path / "bag", msgs))
    assert info.pose_topic is None and "several pose topics" in info.notes[0]
    assert inspect_bag(tmp_path / "bag", pose_topic="/pose2").pose_topic == "/pose2"
    with pytest.raises(TopicError, match=r"pose topic /x is not in the bag"):
        inspect_bag(tmp_path / "bag", pose_topic="/x")


@pytest.mark.realdata
def test_real_ros1_bag(ros):
    path = ros.REALDATA / "ros1_bag" / "test.bag"
    if not path.exists():
        pytest.skip("../shared/realdata/ros1_bag/test.bag absent")
    info = inspect_bag(path)
    assert info.cloud_topic == "/luminar_pointcloud" and info.frames == 5
    assert info.pose_topic == "/base_pose_ground_truth"
    # its Odometry runs on simulated time (60 s) and the clouds on wall time (2020)
    with pytest.raises(PoseError, match=r"different clocks"):
        read_frames(path)
    fs = read_frames(path, ReadSettings(pose_topic="", allow_no_pose=True))
    sizes = [len(f.points) for f in fs.frames]
    assert sizes == [35707, 36055, 36267, 36457, 36336]
    assert fs.frames[0].stamp == 1583971570015299642
    assert np.isfinite(fs.frames[0].points).all()
    assert 1.0 < np.linalg.norm(fs.frames[0].points, axis=1).mean() < 300.0


@pytest.mark.realdata
def test_real_velodyne_packets_need_no_pose(ros, tmp_path):
    path = ros.REALDATA / "vlp16_packets" / "bag"
    if not path.exists():
        pytest.skip("../shared/realdata/vlp16_packets absent")
    fs = read_frames(path)
    assert len(fs) == 4 and fs.pose_topic is None
    assert all(len(f.points) > 10000 for f in fs.frames)
    assert np.array_equal(fs.frames[0].position, np.zeros(3))
    dual = read_frames(path, ReadSettings(return_mode="dual"))
    assert len(dual.frames[0].points) > len(fs.frames[0].points)
    copy = tmp_path / "bag"
    shutil.copytree(path, copy)
    db = next(copy.glob("*.db3"))
    db.chmod(0o644)
    db.write_bytes(db.read_bytes()[:-100])
    with pytest.raises(BagError, match=r"is truncated"):
        read_frames(copy)
