"""ROS 2 messages built from arrays: the type store, headers, poses, paths, TF and clouds.

The store is rosbags' ROS 2 Humble set plus three packages it lacks, registered from
their message definitions: ``octomap_msgs/msg/Octomap`` (RViz's OctoMap plugin),
``grid_map_msgs/msg/GridMap`` (the ROS 2 layout: header, ``GridMapInfo`` with the
map centre's pose, named float32 layers) and ``foxglove_msgs/msg/Grid`` (Foxglove's
own grid, as its ``ros_foxglove_msgs`` package defines it for ROS 2). Every message an
exporter writes is built here, in :mod:`alte.export.maps` or in :mod:`alte.export.grids`,
as the store's own classes (typed fields).
"""

from __future__ import annotations

from functools import cache
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray
from rosbags.interfaces import Nodetype
from rosbags.typesys import Stores, get_types_from_msg, get_typestore
from rosbags.typesys.store import Typestore

from alte.io.bags.pointcloud2 import encode_pointcloud2, make_header, make_time

if TYPE_CHECKING:  # rosbags declares its message classes' types for checkers only
    from rosbags.interfaces.typing import FieldDesc, Typesdict
    from rosbags.typesys.store import Msgarg, MsgType

__all__ = ["EXTRA_MSGDEFS", "blank", "cloud_msg", "header", "path_msg", "pose", "pose_stamped",
           "tf_msg", "time_msg", "typestore"]

#: Message definitions registered on top of ROS 2 Humble (ROS 2 versions of the packages).
EXTRA_MSGDEFS: dict[str, str] = {
    "octomap_msgs/msg/Octomap": (
        "std_msgs/Header header\n"
        "bool binary\n"
        "string id\n"
        "float64 resolution\n"
        "int8[] data\n"),
    "grid_map_msgs/msg/GridMapInfo": (
        "float64 resolution\n"
        "float64 length_x\n"
        "float64 length_y\n"
        "geometry_msgs/Pose pose\n"),
    "grid_map_msgs/msg/GridMap": (
        "std_msgs/Header header\n"
        "grid_map_msgs/GridMapInfo info\n"
        "string[] layers\n"
        "string[] basic_layers\n"
        "std_msgs/Float32MultiArray[] data\n"
        "uint16 outer_start_index\n"
        "uint16 inner_start_index\n"),
    # foxglove/schemas ros_foxglove_msgs/ros2 (comments left out)
    "foxglove_msgs/msg/Vector2": (
        "float64 x\n"
        "float64 y\n"),
    "foxglove_msgs/msg/PackedElementField": (
        "string name\n"
        "uint32 offset\n"
        "uint8 UNKNOWN=0\n"
        "uint8 UINT8=1\n"
        "uint8 INT8=2\n"
        "uint8 UINT16=3\n"
        "uint8 INT16=4\n"
        "uint8 UINT32=5\n"
        "uint8 INT32=6\n"
        "uint8 FLOAT32=7\n"
        "uint8 FLOAT64=8\n"
        "uint8 type\n"),
    "foxglove_msgs/msg/Grid": (
        "builtin_interfaces/Time timestamp\n"
        "string frame_id\n"
        "geometry_msgs/Pose pose\n"
        "uint32 column_count\n"
        "foxglove_msgs/Vector2 cell_size\n"
        "uint32 row_stride\n"
        "uint32 cell_stride\n"
        "foxglove_msgs/PackedElementField[] fields\n"
        "uint8[] data\n"),
}

_NUMPY = {"bool": np.bool_, "int8": np.int8, "uint8": np.uint8, "byte": np.uint8,
          "char": np.uint8, "int16": np.int16, "uint16": np.uint16, "int32": np.int32,
          "uint32": np.uint32, "int64": np.int64, "uint64": np.uint64,
          "float32": np.float32, "float64": np.float64}


@cache
def typestore() -> Typestore:
    """ROS 2 Humble types plus :data:`EXTRA_MSGDEFS` (one store per process)."""
    store = get_typestore(Stores.ROS2_HUMBLE)
    types: Typesdict = {}
    for name, text in EXTRA_MSGDEFS.items():
        types.update(get_types_from_msg(text, name))
    store.register(types)
    return store


def _blank_field(desc: FieldDesc) -> Msgarg:
    """Default value of one field definition (rosbags' ``(node type, details)`` pair)."""
    if desc[0] == Nodetype.NAME:
        return blank(desc[1])
    if desc[0] == Nodetype.BASE:
        base = desc[1][0]
        return "" if base in {"string", "wstring"} else _NUMPY[base](0).item()
    inner, size = desc[1]
    if inner[0] == Nodetype.BASE and inner[1][0] in _NUMPY:
        return np.zeros(size if desc[0] == Nodetype.ARRAY else 0, dtype=_NUMPY[inner[1][0]])
    if desc[0] == Nodetype.ARRAY:
        if inner[0] == Nodetype.NAME:
            return [blank(inner[1]) for _ in range(size)]
        return [str(_blank_field(inner)) for _ in range(size)]
    return []


def blank(msgtype: str, **values: Msgarg) -> MsgType:
    """A ``msgtype`` message with every field at its ROS default except ``values``."""
    store = typestore()
    fields = store.fielddefs[msgtype][1]
    given = {name: values[name] if name in values else _blank_field(definition)
             for name, definition in fields}
    unknown = set(values) - {name for name, _ in fields}
    if unknown:
        raise TypeError(f"{msgtype} has no field(s) {sorted(unknown)}")
    return store.types[msgtype](**given)


def time_msg(stamp_ns: int) -> MsgType:
    """``builtin_interfaces/msg/Time``."""
    return make_time(stamp_ns, typestore())


def header(stamp_ns: int, frame_id: str) -> MsgType:
    """``std_msgs/msg/Header``."""
    return make_header(stamp_ns, frame_id, typestore())


def pose(position: NDArray[np.float64], quaternion: NDArray[np.float64]) -> MsgType:
    """``geometry_msgs/msg/Pose`` from a position and an (x, y, z, w) quaternion."""
    types = typestore().types
    return types["geometry_msgs/msg/Pose"](
        types["geometry_msgs/msg/Point"](*map(float, position)),
        types["geometry_msgs/msg/Quaternion"](*map(float, quaternion)))


def pose_stamped(stamp_ns: int, frame_id: str, position: NDArray[np.float64],
                 quaternion: NDArray[np.float64]) -> MsgType:
    """``geometry_msgs/msg/PoseStamped``."""
    return typestore().types["geometry_msgs/msg/PoseStamped"](
        header(stamp_ns, frame_id), pose(position, quaternion))


def path_msg(stamp_ns: int, frame_id: str, stamps: NDArray[np.int64],
             positions: NDArray[np.float64], quaternions: NDArray[np.float64]) -> MsgType:
    """``nav_msgs/msg/Path`` through the given poses (each stamped with its own time)."""
    poses = [pose_stamped(int(s), frame_id, p, q)
             for s, p, q in zip(stamps, positions, quaternions, strict=True)]
    return typestore().types["nav_msgs/msg/Path"](header(stamp_ns, frame_id), poses)


def tf_msg(stamp_ns: int, parent: str, child: str, translation: NDArray[np.float64],
           quaternion: NDArray[np.float64]) -> MsgType:
    """``tf2_msgs/msg/TFMessage`` holding one ``parent -> child`` transform."""
    types = typestore().types
    transform = types["geometry_msgs/msg/Transform"](
        types["geometry_msgs/msg/Vector3"](*map(float, translation)),
        types["geometry_msgs/msg/Quaternion"](*map(float, quaternion)))
    stamped = types["geometry_msgs/msg/TransformStamped"](header(stamp_ns, parent), child,
                                                          transform)
    return types["tf2_msgs/msg/TFMessage"]([stamped])


def cloud_msg(points: NDArray[np.float64], stamp_ns: int, frame_id: str) -> MsgType:
    """``sensor_msgs/msg/PointCloud2`` of (N, 3) points (float32 x, y, z)."""
    return encode_pointcloud2(points, stamp_ns, frame_id, typestore())
