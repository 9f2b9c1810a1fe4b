"""The shapes of the ROS messages alte reads, as structural types.

rosbags deserializes each message into a class generated from its definition, so a
message is typed by the fields it has, not by a base class: these protocols name the
fields the readers use (read-only, so any message class with those fields fits, as do
the plain namespaces tests build). Reading code narrows rosbags' ``object`` to one of
them by the connection's message type, which names the class rosbags built.
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

    @property
    def sec(self) -> int: ...
    @property
    def nanosec(self) -> int: ...


class HeaderMsg(Protocol):
    """``std_msgs/msg/Header``: stamp and frame."""

    @property
    def stamp(self) -> TimeMsg: ...
    @property
    def frame_id(self) -> str: ...


class StampedMsg(Protocol):
    """Any message with a header (clouds, scans, stamped poses)."""

    @property
    def header(self) -> HeaderMsg: ...


class XYZMsg(Protocol):
    """``geometry_msgs/msg/Point`` or ``Vector3``."""

    @property
    def x(self) -> float: ...
    @property
    def y(self) -> float: ...
    @property
    def z(self) -> float: ...


class QuaternionMsg(XYZMsg, Protocol):
    """``geometry_msgs/msg/Quaternion`` (x, y, z, w)."""

    @property
    def w(self) -> float: ...


class PoseMsg(Protocol):
    """``geometry_msgs/msg/Pose``."""

    @property
    def position(self) -> XYZMsg: ...
    @property
    def orientation(self) -> QuaternionMsg: ...


class PoseStampedMsg(StampedMsg, Protocol):
    """``geometry_msgs/msg/PoseStamped``."""

    @property
    def pose(self) -> PoseMsg: ...


class _PoseWithCovarianceMsg(Protocol):
    @property
    def pose(self) -> PoseMsg: ...


class OdometryMsg(StampedMsg, Protocol):
    """``nav_msgs/msg/Odometry`` (only its pose is read)."""

    @property
    def child_frame_id(self) -> str: ...
    @property
    def pose(self) -> _PoseWithCovarianceMsg: ...


class _TransformMsg(Protocol):
    @property
    def translation(self) -> XYZMsg: ...
    @property
    def rotation(self) -> QuaternionMsg: ...


class TransformStampedMsg(StampedMsg, Protocol):
    """``geometry_msgs/msg/TransformStamped``."""

    @property
    def child_frame_id(self) -> str: ...
    @property
    def transform(self) -> _TransformMsg: ...


class TFMessageMsg(Protocol):
    """``tf2_msgs/msg/TFMessage``."""

    @property
    def transforms(self) -> Sequence[TransformStampedMsg]: ...


class PointFieldMsg(Protocol):
    """``sensor_msgs/msg/PointField``."""

    @property
    def name(self) -> str: ...
    @property
    def offset(self) -> int: ...
    @property
    def datatype(self) -> int: ...
    @property
    def count(self) -> int: ...


class PointCloud2Msg(StampedMsg, Protocol):
    """``sensor_msgs/msg/PointCloud2``: layout fields and the raw data buffer."""

    @property
    def height(self) -> int: ...
    @property
    def width(self) -> int: ...
    @property
    def fields(self) -> Sequence[PointFieldMsg]: ...
    @property
    def is_bigendian(self) -> bool: ...
    @property
    def point_step(self) -> int: ...
    @property
    def row_step(self) -> int: ...
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
