"""IMU topics written and read back; per-point time fields of PointCloud2."""

import numpy as np
import pytest
from rosbags.typesys import Stores, get_typestore

from alte.errors import TopicError
from alte.io.bags.imu import ImuSamples, imu_topic, read_imu
from alte.io.bags.pointcloud2 import decode_timed, encode_pointcloud2
from alte.io.bags.writer import write_bag
from alte.types import Mount

STORE = get_typestore(Stores.ROS2_HUMBLE)
STAMP = 1_700_000_000_500_000_000


def _bag(path, imu=None):
    clouds = [(STAMP + k * 10**8, np.ones((3, 3)) * k) for k in range(3)]
    stamps = np.array([c[0] for c in clouds])
    return write_bag(path, clouds, stamps, np.zeros((3, 3)), np.tile([0, 0, 0, 1.0], (3, 1)),
                     Mount(), imu=imu)


def test_imu_round_trip_with_its_mount(tmp_path):
    n = 50
    rng = np.random.default_rng(0)
    samples = ImuSamples(STAMP + 5_000_000 * np.arange(n), rng.normal(size=(n, 3)),
                         rng.normal(size=(n, 3)) + np.array([0.0, 0.0, 9.81]), "imu_link",
                         Mount(np.array([0.0, 0.0, 0.03])), 0.005, 0.06)
    bag = _bag(tmp_path / "bag", samples)
    assert imu_topic(bag) == "/imu"
    back = read_imu(bag)
    assert len(back) == n and back.rate_hz == pytest.approx(200.0)
    assert np.array_equal(back.stamps, samples.stamps)
    assert np.allclose(back.angular_velocity, samples.angular_velocity)
    assert np.allclose(back.linear_acceleration, samples.linear_acceleration)
    assert back.frame_id == "imu_link" and np.allclose(back.mount.translation, [0, 0, 0.03])


def test_a_bag_without_imu(tmp_path):
    bag = _bag(tmp_path / "bag")
    assert imu_topic(bag) is None
    with pytest.raises(TopicError, match="no IMU topic"):
        read_imu(bag)


@pytest.mark.parametrize(("name", "values", "seconds"), [
    ("time", np.array([0.0, 0.025, 0.05], np.float32), [0.0, 0.025, 0.05]),  # Velodyne
    ("t", np.array([0, 25_000_000, 50_000_000], np.uint32), [0.0, 0.025, 0.05]),  # Ouster
    ("timestamp", STAMP / 1e9 + np.array([0.0, 0.025, 0.05]), [0.0, 0.025, 0.05]),  # Hesai
    ("timestamp", STAMP + np.array([0.0, 25e6, 50e6]), [0.0, 0.025, 0.05]),  # Livox ns
])
def test_point_times_in_seconds_from_the_stamp(name, values, seconds):
    pts = np.array([[1.0, 0, 0], [np.nan, 0, 0], [3.0, 0, 0]])
    msg = encode_pointcloud2(pts, STAMP, "lidar", STORE, extra_fields={name: values})
    points, times, dropped = decode_timed(msg, STAMP)
    assert dropped == 1 and len(points) == 2
    assert times == pytest.approx([seconds[0], seconds[2]], abs=1e-6)


def test_no_time_field():
    msg = encode_pointcloud2(np.ones((2, 3)), STAMP, "lidar", STORE)
    assert decode_timed(msg, STAMP)[1] is None
