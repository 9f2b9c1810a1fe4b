"""The shapes of the ROS messages alte reads, as structural types.

rosbags deserializes each message into a class generated from its definition, so a
message is typed by the fields it has, not by a base class: these protocols name the
fields the readers use, so any message class with those fields fits (as do the plain
namespaces tests build): scalars are attributes, fields holding messages, lists or
arrays read-only properties, which any class whose field has a fitting shape satisfies.
Reading code narrows rosbags' ``object`` to one of them by the connection's message
type, which names the class rosbags built.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Protocol, runtime_checkable

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "HeaderMsg",
    "OdometryMsg",
    "PointCloud2Msg",
    "PointFieldMsg",
    "PoseMsg",
    "PoseStampedMsg",
    "QuaternionMsg",
    "StampedMsg",
    "TFMessageMsg",
    "TimeMsg",
    "TransformStampedMsg",
    "VelodyneScanMsg",
    "XYZMsg",
]


class TimeMsg(Protocol):
    """``builtin_interfaces/msg/Time``."""

    sec: int
    nanosec: int


class HeaderMsg(Protocol):
    """``std_msgs/msg/Header``: stamp and frame."""

    frame_id: str

    @property
    def stamp(self) -> TimeMsg: ...


class StampedMsg(Protocol):
    """A message with a header (clouds, scans, stamped poses)."""

    @property
    def header(self) -> HeaderMsg: ...


class XYZMsg(Protocol):
    """``geometry_msgs/msg/Point`` or ``Vector3``."""

    x: float
    y: float
    z: float


class QuaternionMsg(XYZMsg, Protocol):
    """``geometry_msgs/msg/Quaternion`` (x, y, z, w)."""

    w: float


class PoseMsg(Protocol):
    """``geometry_msgs/msg/Pose``."""

    @property
    def position(self) -> XYZMsg: ...
    @property
    def orientation(self) -> QuaternionMsg: ...


class _WithPoseMsg(Protocol):
    """A message holding a pose (``PoseStamped``, ``PoseWithCovariance``)."""

    @property
    def pose(self) -> PoseMsg: ...


class PoseStampedMsg(StampedMsg, _WithPoseMsg, Protocol):
    """``geometry_msgs/msg/PoseStamped``."""


class OdometryMsg(StampedMsg, Protocol):
    """``nav_msgs/msg/Odometry`` (only its pose is read)."""

    child_frame_id: str

    @property
    def pose(self) -> _WithPoseMsg: ...


class _TransformMsg(Protocol):
    @property
    def translation(self) -> XYZMsg: ...
    @property
    def rotation(self) -> QuaternionMsg: ...


class TransformStampedMsg(StampedMsg, Protocol):
    """``geometry_msgs/msg/TransformStamped``."""

    child_frame_id: str

    @property
    def transform(self) -> _TransformMsg: ...


class TFMessageMsg(Protocol):
    """``tf2_msgs/msg/TFMessage``."""

    @property
    def transforms(self) -> Sequence[TransformStampedMsg]: ...


class PointFieldMsg(Protocol):
    """``sensor_msgs/msg/PointField``."""

    name: str
    offset: int
    datatype: int
    count: int


class PointCloud2Msg(StampedMsg, Protocol):
    """``sensor_msgs/msg/PointCloud2``: layout fields and the raw data buffer."""

    height: int
    width: int
    @property
    def fields(self) -> Sequence[PointFieldMsg]: ...
    is_bigendian: bool
    point_step: int
    row_step: int
    @property
    def data(self) -> NDArray[np.uint8] | bytes: ...


class _VelodynePacketMsg(Protocol):
    @property
    def data(self) -> ArrayLike: ...


@runtime_checkable
class VelodyneScanMsg(Protocol):
    """``velodyne_msgs/msg/VelodyneScan``: raw packets of 1206 bytes each (only they are read).

    Runtime-checkable: the decoder refuses anything without packets with a clear error.
    """

    @property
    def packets(self) -> Sequence[_VelodynePacketMsg]: ...
