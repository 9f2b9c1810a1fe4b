"""Tests for alte.io.poses.pose: cleaning pose samples and interpolating them at scan stamps."""

from __future__ import annotations

import warnings
from types import SimpleNamespace

import numpy as np
import pytest
from scipy.spatial.transform import Rotation, Slerp

from alte.errors import PoseError
from alte.io.poses.pose import PoseTrack, pose_records, select_tf_child

NS = 1_000_000_000


def track(n=11, dt=0.1, t0=100.0):
    """Rotating about z at 0.5 rad/s and moving along x at 2 m/s."""
    t = t0 + dt * np.arange(n)
    stamps = np.round(t * NS).astype(np.int64)
    rot = Rotation.from_euler("zyx", np.column_stack([0.5 * (t - t0), 0.2 * np.sin(t), 0 * t]))
    pos = np.column_stack([2.0 * (t - t0), np.cos(t), 0 * t])
    return stamps, pos, rot.as_quat()


def test_interpolation_matches_linear_and_scipy_slerp():
    stamps, pos, quat = track()
    tr = PoseTrack.from_samples(stamps, pos, quat)
    query = np.sort(np.random.default_rng(0).integers(stamps[0], stamps[-1], 50))
    got = tr.interpolate(query)
    assert got.valid.all() and not got.outside.any() and not got.in_gap.any()
    for axis in range(3):
        np.testing.assert_allclose(got.positions[:, axis], np.interp(query, stamps, pos[:, axis]))
    ref = Slerp((stamps - stamps[0]) / NS, Rotation.from_quat(quat))((query - stamps[0]) / NS)
    assert np.allclose((ref.inv() * Rotation.from_quat(got.quaternions)).magnitude(), 0, atol=1e-9)


def test_exact_sample_stamps_return_the_samples_bit_for_bit():
    stamps, pos, quat = track()
    got = PoseTrack.from_samples(stamps, pos, quat).interpolate(stamps)
    assert np.array_equal(got.positions, pos) and np.array_equal(got.quaternions, quat)
    assert np.array_equal(got.offset_s, np.zeros(len(stamps)))


def test_offset_and_angular_rate():
    stamps, pos, quat = track()
    got = PoseTrack.from_samples(stamps, pos, quat).interpolate([stamps[3] + NS // 40])
    assert got.offset_s[0] == pytest.approx(0.025)
    expected = (Rotation.from_quat(quat[3]).inv() * Rotation.from_quat(quat[4])).magnitude() / 0.1
    assert got.angular_rate[0] == pytest.approx(expected)
    assert 0.4 < got.angular_rate[0] < 1.0


def test_outside_range_is_invalid_never_extrapolated():
    stamps, pos, quat = track()
    got = PoseTrack.from_samples(stamps, pos, quat).interpolate(
        [stamps[0] - 1, stamps[0], stamps[-1], stamps[-1] + 1]
    )
    assert got.outside.tolist() == [True, False, False, True]
    assert got.valid.tolist() == [False, True, True, False]
    assert np.isnan(got.positions[[0, 3]]).all() and np.isnan(got.quaternions[[0, 3]]).all()
    assert got.offset_s[0] == pytest.approx(1e-9)


def test_stamps_inside_a_gap_are_invalid():
    stamps = np.array([0, 1, 2, 12, 13]) * NS // 10
    pos = np.zeros((5, 3))
    quat = np.tile([0.0, 0.0, 0.0, 1.0], (5, 1))
    tr = PoseTrack.from_samples(stamps + 5 * NS, pos, quat)
    got = tr.interpolate(np.array([10, 50, 120, 125]) * NS // 100 + 5 * NS, max_gap_s=0.5)
    assert got.in_gap.tolist() == [False, True, False, False]
    assert got.valid.tolist() == [True, False, True, True]
    assert tr.interpolate([5 * NS + NS // 2], max_gap_s=2.0).valid[0]


def test_duplicates_and_reordering_are_counted():
    stamps, pos, quat = track(6)
    order = [0, 2, 1, 3, 3, 5, 4]
    tr = PoseTrack.from_samples(stamps[order], pos[order], quat[order], "vicon")
    assert tr.duplicates == 1 and tr.reordered == 2
    assert np.array_equal(tr.stamps, stamps) and np.array_equal(tr.positions, pos)


def test_zero_and_nan_quaternions_name_sample_and_stamp():
    stamps, pos, quat = track(5)
    quat[3] = 0.0
    with pytest.raises(PoseError, match=rf"vicon: sample 3 \(stamp {stamps[3]} ns\)"):
        PoseTrack.from_samples(stamps, pos, quat, "vicon")
    quat[3] = [np.nan, 0, 0, 1]
    with pytest.raises(PoseError, match=r"sample 3"):
        PoseTrack.from_samples(stamps, pos, quat, "vicon")
    stamps, pos, quat = track(5)
    pos[1, 2] = np.inf
    with pytest.raises(PoseError, match=r"sample 1"):
        PoseTrack.from_samples(stamps, pos, quat, "vicon")


def test_non_unit_quaternions_are_normalized_with_a_warning():
    stamps, pos, quat = track(5)
    scaled = quat * np.array([1.0, 2.0, 1.0, 1.0 + 1e-7, 1.0])[:, None]
    with pytest.warns(UserWarning, match=r"vicon: 1 quaternions are not unit"):
        tr = PoseTrack.from_samples(stamps, pos, scaled, "vicon")
    np.testing.assert_allclose(np.linalg.norm(tr.quaternions, axis=1), 1.0, atol=1e-15)
    np.testing.assert_allclose(tr.quaternions, quat, atol=1e-12)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        PoseTrack.from_samples(stamps, pos, quat * (1 + 1e-6), "vicon")


def test_quaternion_signs_are_made_continuous():
    stamps, pos, quat = track(6)
    flipped = quat * np.array([1, -1, -1, 1, -1, 1])[:, None]
    tr = PoseTrack.from_samples(stamps, pos, flipped)
    assert (np.einsum("ij,ij->i", tr.quaternions[1:], tr.quaternions[:-1]) > 0).all()
    np.testing.assert_allclose(tr.quaternions, quat)
    mid = tr.interpolate([(stamps[1] + stamps[2]) // 2])
    assert mid.angular_rate[0] < 1.0


def test_wrong_stamp_unit_is_an_error():
    stamps, pos, quat = track(5, t0=100.0)
    as_seconds = PoseTrack.from_samples(np.arange(100, 105), pos, quat, "mocap")
    with pytest.raises(PoseError, match=r"mocap: scan stamps are ~1e\+09 times larger.*seconds"):
        as_seconds.interpolate([stamps[2]])
    tr = PoseTrack.from_samples(stamps, pos, quat, "mocap")
    with pytest.raises(PoseError, match=r"pose stamps are ~1e\+09 times larger"):
        tr.interpolate([102])
    far = tr.interpolate([stamps[-1] + 10 * NS])
    assert far.outside[0]
    as_ms = PoseTrack.from_samples(np.arange(5) * 100 + 100_000, pos, quat, "mocap")
    with pytest.raises(PoseError, match=r"~1e\+06 times larger.*milliseconds"):
        as_ms.interpolate([stamps[2]])
    sim = PoseTrack.from_samples(np.arange(5) * NS // 10, pos, quat, "sim")  # 0 .. 0.4 s
    assert sim.interpolate([200 * NS]).outside[0]


def test_single_sample_track():
    tr = PoseTrack.from_samples([5 * NS], [[1, 2, 3]], [[0, 0, 0, 1]])
    got = tr.interpolate([5 * NS, 5 * NS + 1])
    assert got.valid.tolist() == [True, False] and got.outside.tolist() == [False, True]


def test_shape_errors():
    with pytest.raises(PoseError, match=r"odom: no pose samples"):
        PoseTrack.from_samples([], np.empty((0, 3)), np.empty((0, 4)), "odom")
    with pytest.raises(PoseError, match=r"odom: expected 2 positions"):
        PoseTrack.from_samples([1, 2], np.zeros((2, 3)), np.zeros((3, 4)), "odom")


def _hdr(sec, nsec, frame):
    return SimpleNamespace(stamp=SimpleNamespace(sec=sec, nanosec=nsec), frame_id=frame)


def _pose(x, w=1.0):
    return SimpleNamespace(position=SimpleNamespace(x=x, y=0.0, z=0.0),
                           orientation=SimpleNamespace(x=0.0, y=0.0, z=0.0, w=w))


def test_pose_records_of_each_type_and_log_time_fallback():
    ps = SimpleNamespace(header=_hdr(0, 0, "map"), pose=_pose(1.0))
    assert pose_records(ps, "geometry_msgs/msg/PoseStamped", 77) == [
        ("map", "", 77, (1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0))]
    odom = SimpleNamespace(header=_hdr(2, 5, "odom"), child_frame_id="base",
                           pose=SimpleNamespace(pose=_pose(2.0)))
    assert pose_records(odom, "nav_msgs/msg/Odometry", 77)[0][:3] == ("odom", "base", 2 * NS + 5)
    tf = SimpleNamespace(header=_hdr(3, 0, "map"), child_frame_id="odom", transform=SimpleNamespace(
        translation=SimpleNamespace(x=1.0, y=2.0, z=3.0),
        rotation=SimpleNamespace(x=0.0, y=0.0, z=0.0, w=1.0)))
    recs = pose_records(SimpleNamespace(transforms=[tf, tf]), "tf2_msgs/msg/TFMessage", 0)
    assert len(recs) == 2 and recs[0][3][:3] == (1.0, 2.0, 3.0)
    with pytest.raises(PoseError, match=r"sensor_msgs/msg/Imu carries no pose"):
        pose_records(ps, "sensor_msgs/msg/Imu", 0)


def test_select_tf_child():
    recs = [("map", "odom", 0, ()), ("odom", "base_link", 0, ()), ("base_link", "lidar", 0, ())]
    assert select_tf_child(recs, "lidar", None, "/tf") == "base_link"
    assert select_tf_child(recs, "lidar", "odom", "/tf") == "odom"
    with pytest.raises(PoseError, match=r"/tf: no transform to body frame 'uav'"):
        select_tf_child(recs, "lidar", "uav", "/tf")
    two = [*recs, ("map", "other", 0, ())]
    with pytest.raises(PoseError, match=r"cannot tell the body frame among .*'other'"):
        select_tf_child(two, "lidar", None, "/tf")
