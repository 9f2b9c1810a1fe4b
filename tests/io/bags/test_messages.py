"""The message shapes name real fields: every member of each protocol is a field of the ROS
definition rosbags uses, nested shapes included, so a typo or a wrong nesting fails here."""

from __future__ import annotations

import collections.abc
import typing

import pytest
from rosbags.interfaces import Nodetype
from rosbags.typesys import Stores, get_typestore

from alte.io.bags import messages
from alte.io.bags.velodyne import register_velodyne_types

STORE = get_typestore(Stores.ROS2_HUMBLE)
register_velodyne_types(STORE)


def _members(shape: type) -> dict[str, object]:
    """Attribute or property name -> its type, inherited protocols included."""
    out: dict[str, object] = {}
    for klass in reversed(shape.__mro__):
        if klass.__module__ != messages.__name__:
            continue
        out.update(typing.get_type_hints(klass))
        for name, value in vars(klass).items():
            if isinstance(value, property) and value.fget is not None:
                out[name] = typing.get_type_hints(value.fget)["return"]
    return out


def _check(shape: type, msgtype: str) -> int:
    """Assert ``shape``'s properties against ``msgtype``'s fields; count the fields checked."""
    fields = dict(STORE.fielddefs[msgtype][1])
    checked = 0
    for name, annotated in _members(shape).items():
        assert name in fields, f"{shape.__name__}.{name} is not a field of {msgtype}"
        node, spec = fields[name]
        checked += 1
        kind = annotated
        if typing.get_origin(annotated) is collections.abc.Sequence:
            assert node in {Nodetype.SEQUENCE, Nodetype.ARRAY}, f"{msgtype}.{name} is no list"
            (node, spec), kind = spec[0], typing.get_args(annotated)[0]
        if isinstance(kind, type) and getattr(kind, "_is_protocol", False):
            assert node == Nodetype.NAME, f"{msgtype}.{name} is not a message"
            checked += _check(kind, spec)
    return checked


@pytest.mark.parametrize(("shape", "msgtype", "fields"), [
    (messages.PoseStampedMsg, "geometry_msgs/msg/PoseStamped", 15),
    (messages.OdometryMsg, "nav_msgs/msg/Odometry", 17),
    (messages.TFMessageMsg, "tf2_msgs/msg/TFMessage", 17),
    (messages.PointCloud2Msg, "sensor_msgs/msg/PointCloud2", 16),
    (messages.VelodyneScanMsg, "velodyne_msgs/msg/VelodyneScan", 2),
])
def test_shapes_are_the_ros_definitions(shape: type, msgtype: str, fields: int) -> None:
    assert _check(shape, msgtype) == fields


def test_velodyne_scan_shape_is_checked_at_run_time() -> None:
    scan = STORE.types["velodyne_msgs/msg/VelodyneScan"]
    header = STORE.types["std_msgs/msg/Header"](
        stamp=STORE.types["builtin_interfaces/msg/Time"](sec=0, nanosec=0), frame_id="v")
    assert isinstance(scan(header=header, packets=[]), messages.VelodyneScanMsg)
    assert not isinstance(header, messages.VelodyneScanMsg)
