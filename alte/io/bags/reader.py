"""Open any ROS bag with rosbags, stream one topic, and pick the cloud/pose topics.

The only place that talks to rosbags' reader: every failure of it (missing
file, truncated or corrupt storage, undecodable message) leaves as a
:class:`~alte.errors.BagError` naming the bag.
"""

from __future__ import annotations

import contextlib
import sqlite3
import struct
from collections.abc import Iterator
from pathlib import Path
from typing import cast

import apsw
import numpy as np
from numpy.typing import NDArray
from rosbags.highlevel import AnyReader, AnyReaderError
from rosbags.rosbag1 import ReaderError as Reader1Error
from rosbags.rosbag2 import ReaderError as Reader2Error
from rosbags.serde import SerdeError
from rosbags.typesys import Stores, get_typestore
from rosbags.typesys.base import TypesysError
from scipy.spatial.transform import Rotation

from alte.errors import BagError, TopicError
from alte.io.bags.messages import StampedMsg
from alte.io.poses.pose import POSE_TYPES, pose_records
from alte.types import Mount

__all__ = [
    "CLOUD_TYPES",
    "PC2_TYPE",
    "SCAN_TYPE",
    "TF_STATIC",
    "detect_topics",
    "first_frame_id",
    "open_bag",
    "read_messages",
    "select_topic",
    "static_mount",
    "topic_listing",
    "topic_table",
]

PC2_TYPE = "sensor_msgs/msg/PointCloud2"
SCAN_TYPE = "velodyne_msgs/msg/VelodyneScan"
CLOUD_TYPES = (PC2_TYPE, SCAN_TYPE)
TF_STATIC = "/tf_static"
#: What rosbags and its storage back-ends raise on unreadable, truncated or corrupt bags.
_READ_ERRORS = (
    AnyReaderError,
    Reader1Error,
    Reader2Error,
    SerdeError,
    TypesysError,
    sqlite3.Error,
    apsw.Error,
    OSError,
    EOFError,
    struct.error,
    ValueError,
    KeyError,
    IndexError,
    AssertionError,
)


@contextlib.contextmanager
def open_bag(path: str | Path) -> Iterator[AnyReader]:
    """Open a ROS 1 ``.bag`` file, a ROS 2 bag folder or a ``.db3``/``.mcap`` file.

    Bags without stored message definitions fall back to the ROS 2 Humble types
    plus ``velodyne_msgs``. Every rosbags failure becomes a :class:`BagError`
    naming ``path``.
    """
    bag = Path(path)
    if not bag.exists():
        raise BagError(f"bag {bag} does not exist")
    _check_sqlite_size(bag)
    try:
        reader = AnyReader([bag], default_typestore=get_typestore(Stores.ROS2_HUMBLE))
        reader.open()
    except _READ_ERRORS as err:
        raise BagError(f"{bag} is not a readable ROS bag (truncated or corrupt?): {err}") from err
    try:
        _register_extra_types(reader)
        yield reader
    finally:
        with contextlib.suppress(*_READ_ERRORS):
            reader.close()


def _check_sqlite_size(bag: Path) -> None:
    """Refuse a truncated ``.db3``: SQLite reads missing tail pages as garbage, silently.

    The file header stores the page size (offset 16) and the page count (offset 28);
    a complete database file is exactly their product.
    """
    for db in [bag] if bag.is_file() else sorted(bag.glob("*.db3")):
        with db.open("rb") as fh:
            head = fh.read(100)
        if db.suffix != ".db3" or len(head) < 100 or not head.startswith(b"SQLite format 3\0"):
            continue  # not SQLite: rosbags reports it
        page = int.from_bytes(head[16:18], "big")
        page = 65536 if page == 1 else page
        pages = int.from_bytes(head[28:32], "big")
        size = db.stat().st_size
        if size % page or size < page * pages:
            raise BagError(
                f"{db} is truncated: {size} bytes, its header says {pages} pages of {page} bytes"
            )


def _register_extra_types(reader: AnyReader) -> None:
    """Make ``velodyne_msgs`` deserializable (bags never store its definition)."""
    if any(c.msgtype == SCAN_TYPE for c in reader.connections):
        from alte.io.bags.velodyne import register_velodyne_types

        register_velodyne_types(reader.typestore)


def read_messages(
    reader: AnyReader, topic: str, path: str | Path, select: frozenset[int] | None = None
) -> Iterator[tuple[int, str, object]]:
    """Yield ``(log_time_ns, msgtype, message)`` of one topic, errors as :class:`BagError`.

    ``message`` is rosbags' instance of the ``msgtype`` class (see :mod:`alte.io.bags.messages`
    for the shapes alte reads). With ``select`` only messages at those indices (in
    log-time order) are decoded; the others are yielded as ``None`` without the cost of
    deserializing them.
    """
    conns = [c for c in reader.connections if c.topic == topic]
    try:
        for i, (conn, log_time, raw) in enumerate(reader.messages(connections=conns)):
            if select is not None and i not in select:
                yield log_time, conn.msgtype, None
                continue
            yield log_time, conn.msgtype, reader.deserialize(raw, conn.msgtype)
    except _READ_ERRORS as err:
        raise BagError(f"{path}: cannot read topic {topic} (truncated or corrupt?): {err}") from err


def topic_table(reader: AnyReader) -> dict[str, tuple[str, int]]:
    """``{topic: (msgtype, count)}`` in name order."""
    return {
        name: (info.msgtype or "<mixed types>", int(info.msgcount))
        for name, info in sorted(reader.topics.items())
    }


def topic_listing(topics: dict[str, tuple[str, int]]) -> str:
    """``topics in the bag: /a [type], ...`` for error messages."""
    if not topics:
        return "the bag has no topics"
    return "topics in the bag: " + ", ".join(f"{n} [{t}]" for n, (t, _) in topics.items())


def select_topic(
    topics: dict[str, tuple[str, int]],
    override: str | None,
    types: tuple[str, ...],
    what: str,
    path: Path,
) -> str | None:
    """The topic to use for ``what``: the override (checked) or the only one of ``types``.

    Returns None when there is no candidate; raises :class:`TopicError` for a bad
    override or an ambiguous choice. An empty override means "none" (returns None).
    """
    if override == "":
        return None
    if override is not None:
        if override not in topics:
            raise TopicError(
                f"{path}: {what} topic {override} is not in the bag; {topic_listing(topics)}"
            )
        if topics[override][0] not in types:
            raise TopicError(
                f"{path}: {what} topic {override} has type {topics[override][0]}, expected one "
                f"of {types}; {topic_listing(topics)}"
            )
        return override
    found = [n for n, (t, _) in topics.items() if t in types and n != TF_STATIC]
    if len(found) > 1:
        raise TopicError(
            f"{path}: several {what} topics ({', '.join(found)}); choose one with the "
            f"{what} topic option; {topic_listing(topics)}"
        )
    return found[0] if found else None


def detect_topics(
    topics: dict[str, tuple[str, int]],
    path: str | Path,
    cloud_topic: str | None = None,
    pose_topic: str | None = None,
) -> tuple[str | None, str | None]:
    """``(cloud_topic, pose_topic)`` picked by message type, or the checked overrides.

    Either is None when the bag has no such topic; ambiguity or a bad override
    is a :class:`TopicError` that lists the bag's topics.
    """
    bag = Path(path)
    cloud = select_topic(topics, cloud_topic, CLOUD_TYPES, "cloud", bag)
    pose = select_topic(topics, pose_topic, POSE_TYPES, "pose", bag)
    return cloud, pose


def first_frame_id(reader: AnyReader, topic: str | None, path: Path) -> str | None:
    """``header.frame_id`` of the first message on ``topic`` (the sensor frame)."""
    if topic is None:
        return None
    for _, _, msg in read_messages(reader, topic, path):
        return str(cast(StampedMsg, msg).header.frame_id)  # clouds and scans have headers
    return None


def static_mount(reader: AnyReader, sensor: str | None, path: Path) -> tuple[Mount | None, str]:
    """Mount and body frame from ``/tf_static``: the chain of transforms from ``sensor`` up
    to the top of its static tree (``base_link -> lidar_mount -> lidar`` gives the mount of
    ``lidar`` on ``base_link``); a cycle is a :class:`TopicError`."""
    if sensor is None or TF_STATIC not in reader.topics:
        return None, ""
    parents: dict[str, tuple[str, tuple[float, ...]]] = {}
    for log_time, msgtype, msg in read_messages(reader, TF_STATIC, path):
        for parent, child, _, values in pose_records(msg, msgtype, log_time):
            parents.setdefault(child, (parent, values))
    if sensor not in parents:
        return None, ""
    matrix, frame, seen = np.eye(4), sensor, [sensor]
    while frame in parents:
        frame, values = parents[frame]
        if frame in seen:
            raise TopicError(f"{path}: {TF_STATIC} has a cycle: {' -> '.join([*seen, frame])}")
        seen.append(frame)
        matrix = _matrix(values) @ matrix
    quaternion = Rotation.from_matrix(matrix[:3, :3]).as_quat()
    return Mount(matrix[:3, 3].copy(), quaternion), frame


def _matrix(values: tuple[float, ...]) -> NDArray[np.float64]:
    """4x4 transform of ``(x, y, z, qx, qy, qz, qw)``."""
    out = np.eye(4)
    out[:3, :3] = Rotation.from_quat(np.asarray(values[3:])).as_matrix()
    out[:3, 3] = values[:3]
    return out
