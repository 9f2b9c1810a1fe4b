"""``sensor_msgs/msg/Imu`` topics: the samples a LiDAR-inertial odometry needs, and where
the IMU sits on the body (its ``/tf_static`` transform).

:func:`read_imu` reads a whole IMU topic into arrays (200 Hz for a 10-minute flight is
120,000 samples of 6 numbers: small beside the scans); :func:`imu_topic` picks the topic.
Orientation, when a driver fills it, is not read: odometry integrates the rates.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol, cast

import numpy as np
from numpy.typing import NDArray

from alte.errors import BagError, TopicError
from alte.io.bags.messages import StampedMsg, XYZMsg
from alte.io.bags.reader import open_bag, read_messages, select_topic, static_mount, topic_table
from alte.io.poses.pose import header_stamp
from alte.types import Mount

__all__ = ["IMU_TYPE", "ImuMsg", "ImuSamples", "imu_topic", "read_imu"]

IMU_TYPE = "sensor_msgs/msg/Imu"


class ImuMsg(StampedMsg, Protocol):
    """``sensor_msgs/msg/Imu`` (rates and specific force only)."""

    @property
    def angular_velocity(self) -> XYZMsg: ...
    @property
    def linear_acceleration(self) -> XYZMsg: ...


@dataclass(frozen=True, eq=False)
class ImuSamples:
    """IMU samples in time order: ``stamps`` (N,) int64 ns, ``angular_velocity`` (N, 3)
    rad/s and ``linear_acceleration`` (N, 3) m/s^2 in the IMU frame ``frame_id``, whose
    pose on the body is ``mount`` (identity when the bag does not say); ``gyro_sigma`` /
    ``accel_sigma`` the per-sample white noise written into the covariances (0: unknown)."""

    stamps: NDArray[np.int64]
    angular_velocity: NDArray[np.float64]
    linear_acceleration: NDArray[np.float64]
    frame_id: str = "imu_link"
    mount: Mount | None = None
    gyro_sigma: float = 0.0
    accel_sigma: float = 0.0

    def __len__(self) -> int:
        return int(self.stamps.shape[0])

    @property
    def rate_hz(self) -> float:
        """Median sample rate."""
        if len(self) < 2:
            return 0.0
        return float(1e9 / np.median(np.diff(self.stamps)))


def imu_topic(path: str | Path, override: str | None = None) -> str | None:
    """The bag's IMU topic (``override`` checked), None without one."""
    with open_bag(path) as reader:
        return select_topic(topic_table(reader), override, (IMU_TYPE,), "IMU", Path(path))


def _vectors(items: Sequence[XYZMsg]) -> NDArray[np.float64]:
    return np.array([[v.x, v.y, v.z] for v in items], dtype=np.float64).reshape(-1, 3)


def read_imu(path: str | Path, topic: str | None = None) -> ImuSamples:
    """Every sample of the bag's IMU topic, sorted by header stamp, with its mount."""
    bag = Path(path)
    with open_bag(bag) as reader:
        name = select_topic(topic_table(reader), topic, (IMU_TYPE,), "IMU", bag)
        if name is None:
            raise TopicError(f"{bag}: no IMU topic ({IMU_TYPE})")
        msgs = [(t, cast(ImuMsg, m)) for t, _, m in read_messages(reader, name, bag)]
        if not msgs:
            raise BagError(f"{bag}: IMU topic {name} has no messages")
        frame = str(msgs[0][1].header.frame_id)
        mount, _ = static_mount(reader, frame, bag)
    stamps = np.array([header_stamp(m.header, t) for t, m in msgs], dtype=np.int64)
    order = np.argsort(stamps, kind="stable")
    gyro = _vectors([m.angular_velocity for _, m in msgs])[order]
    accel = _vectors([m.linear_acceleration for _, m in msgs])[order]
    if not (np.isfinite(gyro).all() and np.isfinite(accel).all()):
        raise BagError(f"{bag}: IMU topic {name} has NaN or infinite samples")
    return ImuSamples(stamps[order], gyro, accel, frame, mount)
