"""Raw ROS 2 bag writing for tests that need bags alte itself would never write."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.typesys import Stores, get_typestore

__all__ = ["TS", "Message", "write_ros2"]

TS = get_typestore(Stores.ROS2_HUMBLE)
#: (topic, message type, log time ns, message)
Message = tuple[str, str, int, Any]


def write_ros2(path: Path, messages: Sequence[Message], storage: str = "sqlite3") -> Path:
    """Write ``messages`` in the given order as a ROS 2 bag folder (no checks at all)."""
    plugin = StoragePlugin.MCAP if storage == "mcap" else StoragePlugin.SQLITE3
    with Writer(path, version=9, storage_plugin=plugin) as writer:
        conns: dict[str, Any] = {}
        for topic, msgtype, _, _ in messages:
            if topic not in conns:
                conns[topic] = writer.add_connection(topic, msgtype, typestore=TS)
        for topic, msgtype, log_time, msg in messages:
            writer.write(conns[topic], int(log_time), TS.serialize_cdr(msg, msgtype))
    return path
