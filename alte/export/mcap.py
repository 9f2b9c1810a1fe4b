"""One ROS 2 MCAP file of a run, for Foxglove Studio and RViz (``ros2 bag play FILE``).

Topics (frame ``map``; the body is ``base_link``):

========================  ==================================  ===================================
topic                     type                                what
========================  ==================================  ===================================
``/alte/cloud``           ``sensor_msgs/msg/PointCloud2``     merged registered cloud (at the end)
``/alte/scan``            ``sensor_msgs/msg/PointCloud2``     each registered scan, at its stamp
``/alte/pose``            ``geometry_msgs/msg/PoseStamped``   body pose per scan
``/tf``                   ``tf2_msgs/msg/TFMessage``          ``map -> base_link`` per scan
``/tf_static``            ``tf2_msgs/msg/TFMessage``          ``map -> alte_local`` (shifted maps)
``/alte/trajectory``      ``nav_msgs/msg/Path``               poses so far, with every map update
``/alte/map/cells``       ``visualization_msgs/msg/MarkerArray``  cube lists coloured by height
``/alte/map/occupancy``   ``nav_msgs/msg/OccupancyGrid``      2D maps: 100 occupied, 0 free, -1
``/alte/map/grid_map``    ``grid_map_msgs/msg/GridMap``       2D maps: ``elevation``, ``occupancy``
``/alte/map/octomap``     ``octomap_msgs/msg/Octomap``        Octomap: binary tree (OctoMap plugin)
========================  ==================================  ===================================

Map topics and ``/tf_static`` are offered reliable + transient-local, so RViz's
latched subscriptions get them on playback. With a timeline (every ``N`` mapped
scans) the map topics are written as the map grows, each stamped with its scan's time;
otherwise once, at the last scan. The file is written through rosbags' MCAP storage
into a temporary folder beside the target and moved onto it when complete.
"""

from __future__ import annotations

import tempfile
from pathlib import Path
from types import TracebackType
from typing import Any

from rosbags.interfaces import Qos, QosDurability, QosHistory, QosLiveliness, QosReliability
from rosbags.interfaces import QosTime as Time
from rosbags.rosbag2 import StoragePlugin, Writer

from alte.fsutil import atomic_path

__all__ = ["MAP_TOPICS", "TOPICS", "McapFile"]

#: Topic -> message type of every topic an export may write.
TOPICS: dict[str, str] = {
    "/alte/cloud": "sensor_msgs/msg/PointCloud2",
    "/alte/scan": "sensor_msgs/msg/PointCloud2",
    "/alte/pose": "geometry_msgs/msg/PoseStamped",
    "/tf": "tf2_msgs/msg/TFMessage",
    "/tf_static": "tf2_msgs/msg/TFMessage",
    "/alte/trajectory": "nav_msgs/msg/Path",
    "/alte/map/cells": "visualization_msgs/msg/MarkerArray",
    "/alte/map/occupancy": "nav_msgs/msg/OccupancyGrid",
    "/alte/map/grid_map": "grid_map_msgs/msg/GridMap",
    "/alte/map/octomap": "octomap_msgs/msg/Octomap",
}
#: Topics offered transient-local (latched): the maps and the static transform.
MAP_TOPICS = frozenset({"/tf_static", "/alte/map/cells", "/alte/map/occupancy",
                        "/alte/map/grid_map", "/alte/map/octomap", "/alte/cloud",
                        "/alte/trajectory"})
_NEVER = Time(0, 0)
_VOLATILE = Qos(QosHistory.KEEP_LAST, 10, QosReliability.RELIABLE, QosDurability.VOLATILE,
                _NEVER, _NEVER, QosLiveliness.AUTOMATIC, _NEVER, False)
_LATCHED = _VOLATILE._replace(depth=1, durability=QosDurability.TRANSIENT_LOCAL)


class McapFile:
    """Write messages to ``path`` (a new ``.mcap`` file; an existing one is refused).

    Use as a context manager; ``put(topic, stamp_ns, message)`` with a topic of
    :data:`TOPICS`. The file appears only when the ``with`` block ends without error.
    """

    def __init__(self, path: Path, overwrite: bool = False) -> None:
        self.path = Path(path)
        self.overwrite = overwrite
        self.counts: dict[str, int] = {}
        self._conns: dict[str, Any] = {}
        self._writer: Writer | None = None

    def __enter__(self) -> McapFile:
        from alte.export.rosmsg import typestore

        self._store = typestore()
        self._atomic = atomic_path(self.path, overwrite=self.overwrite)
        self._target = self._atomic.__enter__()
        self._tmp = tempfile.TemporaryDirectory(dir=self.path.parent, prefix=".alte-mcap.")
        self._bag = Path(self._tmp.name) / "export"
        self._writer = Writer(self._bag, version=Writer.VERSION_LATEST,
                              storage_plugin=StoragePlugin.MCAP)
        self._writer.open()
        return self

    def put(self, topic: str, stamp: int, message: Any) -> None:
        """Serialise ``message`` and log it on ``topic`` at ``stamp`` (ns)."""
        if self._writer is None:
            raise RuntimeError("McapFile.put outside its with block")
        if topic not in self._conns:
            qos = _LATCHED if topic in MAP_TOPICS else _VOLATILE
            self._conns[topic] = self._writer.add_connection(
                topic, TOPICS[topic], typestore=self._store, offered_qos_profiles=[qos])
        data = self._store.serialize_cdr(message, TOPICS[topic])
        self._writer.write(self._conns[topic], int(stamp), data)
        self.counts[topic] = self.counts.get(topic, 0) + 1

    def __exit__(self, kind: type[BaseException] | None, error: BaseException | None,
                 trace: TracebackType | None) -> None:
        try:
            if self._writer is not None:
                self._writer.close()
                self._writer = None
            if kind is None:
                (self._bag / "export.mcap").replace(self._target)
        finally:
            self._tmp.cleanup()
            self._atomic.__exit__(kind, error, trace)

