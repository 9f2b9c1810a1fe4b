"""One ROS 2 MCAP file of a run, for Foxglove Studio and RViz (``ros2 bag play FILE``).

Topics (frame ``map``; the body is ``base_link``):

=======================  ======================================  =================================
topic                    type                                    what
=======================  ======================================  =================================
``/alte/cloud``          ``sensor_msgs/msg/PointCloud2``         merged registered cloud
``/alte/scan``           ``sensor_msgs/msg/PointCloud2``         each scan, at its stamp
``/alte/pose``           ``geometry_msgs/msg/PoseStamped``       body pose per scan
``/tf``                  ``tf2_msgs/msg/TFMessage``              ``map -> base_link`` per scan
``/tf_static``           ``tf2_msgs/msg/TFMessage``              ``map -> alte_local`` (shifted)
``/alte/trajectory``     ``nav_msgs/msg/Path``                   poses (whole flight, or so far)
``/alte/map/cells``      ``visualization_msgs/msg/MarkerArray``  cube lists coloured by height
``/alte/map/occupancy``  ``nav_msgs/msg/OccupancyGrid``          0 free, 100 occupied, -1 unseen
``/alte/map/grid``       ``foxglove_msgs/msg/Grid``              height + occupancy (Foxglove)
``/alte/map/grid_map``   ``grid_map_msgs/msg/GridMap``           2D: ``elevation``, ``occupancy``
``/alte/map/octomap``    ``octomap_msgs/msg/Octomap``            Octomap's tree (OctoMap plugin)
=======================  ======================================  =================================

Map topics and ``/tf_static`` are offered reliable + transient-local, so RViz's
latched subscriptions get them on playback. Messages may be *opening* ones (the final
map, the whole trajectory and the merged cloud, stamped with the file's start time so
a viewer shows them from the first instant): they are kept until the end and written
first. The file is written with the ``mcap`` library (Foxglove's reference writer):
zstd-compressed chunks with CRCs, a data-section CRC, message indexes and statistics,
every message in log-time order. Streamed messages go to a plain MCAP in a temporary
folder beside the target; the final file is assembled from it when the ``with`` block
ends without error and moved onto the target.
"""

from __future__ import annotations

import tempfile
from importlib.metadata import version
from pathlib import Path
from types import TracebackType

import yaml
from mcap.reader import make_reader
from mcap.writer import CompressionType, Writer
from rosbags.interfaces import Qos, QosDurability, QosHistory, QosLiveliness, QosReliability
from rosbags.interfaces import QosTime as Time
from rosbags.rosbag2.metadata import dump_qos_v9
from rosbags.typesys.store import Typestore

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
    "/alte/map/grid": "foxglove_msgs/msg/Grid",
    "/alte/map/grid_map": "grid_map_msgs/msg/GridMap",
    "/alte/map/octomap": "octomap_msgs/msg/Octomap",
}
#: Topics offered transient-local (latched): the maps and the static transform.
MAP_TOPICS = frozenset({"/tf_static", "/alte/map/cells", "/alte/map/occupancy",
                        "/alte/map/grid", "/alte/map/grid_map", "/alte/map/octomap",
                        "/alte/cloud", "/alte/trajectory"})
_NEVER = Time(0, 0)
_VOLATILE = Qos(QosHistory.KEEP_LAST, 10, QosReliability.RELIABLE, QosDurability.VOLATILE,
                _NEVER, _NEVER, QosLiveliness.AUTOMATIC, _NEVER, False)
_LATCHED = _VOLATILE._replace(depth=1, durability=QosDurability.TRANSIENT_LOCAL)
_STREAM = "stream.mcap"


def _qos(topic: str) -> str:
    """rosbag2's ``offered_qos_profiles`` channel metadata (YAML) of ``topic``."""
    text: str = yaml.safe_dump(dump_qos_v9([_LATCHED if topic in MAP_TOPICS else _VOLATILE]),
                               default_flow_style=False)
    return text.strip()


class _Channels:
    """Schemas and channels of one MCAP writer, registered on first use per topic."""

    def __init__(self, writer: Writer, store: Typestore) -> None:
        self.writer, self.store = writer, store
        self.schemas: dict[str, int] = {}
        self.ids: dict[str, int] = {}

    def __call__(self, topic: str) -> int:
        if topic not in self.ids:
            msgtype = TOPICS[topic]
            if msgtype not in self.schemas:
                text, _ = self.store.generate_msgdef(msgtype, ros_version=2)
                self.schemas[msgtype] = self.writer.register_schema(
                    msgtype, "ros2msg", text.encode())
            self.ids[topic] = self.writer.register_channel(
                topic, "cdr", self.schemas[msgtype], {"offered_qos_profiles": _qos(topic)})
        return self.ids[topic]


class McapFile:
    """Write messages to ``path`` (a new ``.mcap`` file; an existing one is refused).

    Use as a context manager; ``put(topic, stamp_ns, message)`` with a topic of
    :data:`TOPICS` streams a message; ``put(..., opening=True)`` keeps it for the start of
    the file (its stamp must not be later than the first streamed one). The file
    appears only when the ``with`` block ends without error.
    """

    def __init__(self, path: Path, overwrite: bool = False) -> None:
        self.path = Path(path)
        self.overwrite = overwrite
        self.counts: dict[str, int] = {}
        self._opening: list[tuple[str, int, bytes]] = []
        self._writer: Writer | None = None

    def __enter__(self) -> McapFile:
        from alte.export.rosmsg import typestore

        self._store = typestore()
        self._atomic = atomic_path(self.path, overwrite=self.overwrite)
        self._target = self._atomic.__enter__()
        self._tmp = tempfile.TemporaryDirectory(dir=self.path.parent, prefix=".alte-mcap.")
        self._sink = (Path(self._tmp.name) / _STREAM).open("wb")
        self._writer = Writer(self._sink, compression=CompressionType.NONE, enable_crcs=False)
        self._writer.start(profile="ros2", library=_library())
        self._channels = _Channels(self._writer, self._store)
        return self

    def put(self, topic: str, stamp: int, message: object, opening: bool = False) -> None:
        """Serialise ``message`` and log it on ``topic`` at ``stamp`` (ns)."""
        if self._writer is None:
            raise RuntimeError("McapFile.put outside its with block")
        data = bytes(self._store.serialize_cdr(message, TOPICS[topic]))
        if opening:
            self._opening.append((topic, int(stamp), data))
        else:
            self._writer.add_message(self._channels(topic), int(stamp), data, int(stamp))
        self.counts[topic] = self.counts.get(topic, 0) + 1

    def __exit__(self, kind: type[BaseException] | None, error: BaseException | None,
                 trace: TracebackType | None) -> None:
        failure = (kind, error, trace)
        try:
            if self._writer is not None:
                self._writer.finish()
                self._writer = None
            self._sink.close()
            if kind is None:
                self._assemble()
        except BaseException as err:  # a failed assembly leaves no file either
            failure = (type(err), err, err.__traceback__)
            raise
        finally:
            self._sink.close()
            self._tmp.cleanup()
            self._atomic.__exit__(*failure)

    def _assemble(self) -> None:
        """The final file: opening messages, then the stream in log-time order."""
        with (Path(self._tmp.name) / _STREAM).open("rb") as source, \
                self._target.open("wb") as sink:
            stream = make_reader(source)
            summary = stream.get_summary()
            start = summary.statistics.message_start_time if summary and summary.statistics \
                and summary.statistics.message_count else None
            late = [s for _, s, _ in self._opening if start is not None and s > start]
            if late:
                raise RuntimeError(f"opening message at {late[0]} ns after the file's start "
                                   f"{start} ns")
            out = Writer(sink, compression=CompressionType.ZSTD, enable_crcs=True,
                         enable_data_crcs=True)
            out.start(profile="ros2", library=_library())
            channels = _Channels(out, self._store)
            for topic, stamp, data in sorted(self._opening, key=lambda m: m[1]):
                out.add_message(channels(topic), stamp, data, stamp)
            for _, channel, message in stream.iter_messages(log_time_order=True):
                out.add_message(channels(channel.topic), message.log_time, message.data,
                                message.publish_time)
            out.finish()


def _library() -> str:
    """The MCAP header's writer: alte over the mcap library."""
    return f"alte {version('alte')}, mcap {version('mcap')}"
