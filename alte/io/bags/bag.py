"""Read ROS 1 ``.bag`` files and ROS 2 bags (sqlite3 or mcap) into posed frames.

Thesis 2.1.3 step 1 ("extract"): every LiDAR scan of the cloud topic becomes one
:class:`~alte.types.Frame` in the sensor frame, with the body pose interpolated at
the scan's header stamp from a pose topic (PoseStamped, Odometry or ``/tf``) and
the sensor mount (``R_S/B^B``, ``[DCM]_S^B`` of eq. 2.2) from ``/tf_static``.
Scans without a usable pose or without points are dropped and counted, never guessed.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import cast

import numpy as np
from numpy.typing import NDArray
from rosbags.highlevel import AnyReader

from alte.errors import BagError, ParameterError, PoseError
from alte.io.bags.messages import PointCloud2Msg, StampedMsg, VelodyneScanMsg
from alte.io.bags.pointcloud2 import decode_timed
from alte.io.bags.reader import SCAN_TYPE, open_bag, read_messages
from alte.io.bags.topics import NO_POSE_NOTE, bag_sources
from alte.io.bags.velodyne import RETURN_MODES
from alte.io.poses.pose import PoseTrack, header_stamp
from alte.params import Record, param
from alte.progress import bar as progress_bar
from alte.types import Counts, Frame, Mount

__all__ = ["NO_POSE_NOTE", "FrameSet", "FrameStream", "ReadCounts", "ReadSettings",
           "evenly_spaced", "read_frames"]

_IDENTITY_Q = np.array([0.0, 0.0, 0.0, 1.0])


@dataclass
class ReadCounts(Counts):
    """What reading a bag's scans kept and dropped, updated as frames stream through."""

    scans_read: int = 0
    scans_skipped: int = 0
    scans_outside_poses: int = 0
    scans_in_pose_gap: int = 0
    scans_empty: int = 0
    points_nonfinite: int = 0
    pose_samples: int = 0
    pose_duplicates: int = 0
    pose_reordered: int = 0
    frames: int = 0


@dataclass
class FrameSet:
    """The posed scans of a bag plus what was dropped on the way (``counts``, ``notes``)."""

    frames: list[Frame]
    mount: Mount
    counts: ReadCounts
    cloud_topic: str
    pose_topic: str | None
    path: Path
    notes: list[str] = field(default_factory=list)

    def __len__(self) -> int:
        return len(self.frames)

    def __iter__(self) -> Iterator[Frame]:
        return iter(self.frames)


def _decode(msg: object, msgtype: str, topic: str, return_mode: str,
            stamp: int) -> tuple[NDArray[np.float64], NDArray[np.float64] | None, int]:
    """Points, per-point times (s from ``stamp``, None without) and dropped points of one
    cloud-topic message; ``msgtype`` names the class rosbags built."""
    if msgtype == SCAN_TYPE:
        from alte.io.bags.velodyne import decode_velodyne_scan

        return decode_velodyne_scan(cast(VelodyneScanMsg, msg), return_mode), None, 0
    return decode_timed(cast(PointCloud2Msg, msg), stamp, topic)


def evenly_spaced(total: int, limit: int | None) -> frozenset[int] | None:
    """At most ``limit`` indices of ``range(total)`` evenly spaced over it (None: all)."""
    if limit is None or limit >= total:
        return None
    if isinstance(limit, bool) or not isinstance(limit, int) or limit < 1:
        raise ParameterError(f"frames={limit!r}: expected a positive integer or None")
    return frozenset(np.unique(np.round(np.linspace(0, total - 1, limit))).astype(int).tolist())


@dataclass(frozen=True)
class ReadSettings(Record):
    """How a bag's scans are read and posed (:class:`FrameStream`, :func:`read_frames`),
    checked before the bag is opened.

    Topics are detected by message type unless given (``pose_topic=""`` forces "no pose
    topic"). Without a pose topic, frames get the identity pose only for raw
    ``VelodyneScan`` packets or with ``allow_no_pose``. ``body_frame`` picks the child
    frame of a ``/tf`` pose topic when ``/tf_static`` does not tell it.
    """

    OWNER = "read"

    max_gap_s: float = param(0.5, lambda v: v > 0, "max_gap_s > 0",
                             "a scan inside a longer gap of the pose track is dropped (s)")
    return_mode: str = param("strongest", lambda v: v in RETURN_MODES, "|".join(RETURN_MODES),
                             "which returns of dual-return Velodyne packets are kept")
    select: frozenset[int] | None = param(None, help="the scans read, by index (None: all)")
    progress: bool = param(False, help="a progress bar over the scans")
    cloud_topic: str | None = param(None, help="the PointCloud2 / VelodyneScan topic "
                                               "(None: detected)")
    pose_topic: str | None = param(None, help='the pose topic (None: detected; "": none)')
    pose_file: Path | None = param(None, help="poses from a TUM file instead of a topic")
    body_frame: str | None = param(None, help="the child frame of a /tf pose topic")
    allow_no_pose: bool = param(False, help="identity poses when there is no pose topic")
    frames: int | None = param(None, lambda v: v >= 1, "frames >= 1",
                               "scans kept, evenly spaced (None: all)")

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.pose_file is not None and self.pose_topic:
            raise ParameterError(f"{self.OWNER}: pose_file and pose_topic exclude each other",
                                 setting=(f"{self.OWNER}.pose_file", f"{self.OWNER}.pose_topic"))


class FrameStream:
    """The posed scans of one bag, read lazily: each iteration streams the bag once.

    Opening resolves the cloud and pose topics, the pose track and the mount (and
    raises for a bad bag before any scan is read); iterating yields one
    :class:`~alte.types.Frame` at a time, so memory holds a frame, never the bag.
    ``counts`` describe the last (or current) iteration.
    """

    def __init__(self, path: str | Path, options: ReadSettings | None = None, *,
                 mount: Mount | None = None, read_all: bool = False) -> None:
        """``options``: what is read (:class:`ReadSettings`); ``mount`` overrides the bag's
        ``/tf_static`` body -> sensor transform; ``read_all``: read every scan even when
        ``options.frames`` selects some (odometry needs them all)."""
        options = options or ReadSettings()
        pose_file, pose_topic = options.pose_file, options.pose_topic
        self.path = Path(path)
        self.notes: list[str] = []
        with open_bag(self.path) as reader:
            self.cloud_topic, self.pose_topic, self.track, self.mount = bag_sources(
                reader, self.path,
                (options.cloud_topic, "" if pose_file else pose_topic, options.body_frame),
                mount=mount, allow_no_pose=options.allow_no_pose or pose_file is not None,
                notes=self.notes)
            self.scans = int(reader.topics[self.cloud_topic].msgcount)
        if pose_file is not None:
            self._use_pose_file(pose_file)
        #: The scans ``frames`` selects (None: all); with ``read_all`` every scan is still
        #: read (odometry needs them) and :attr:`selection` only says which go on.
        self.selection = evenly_spaced(self.scans, options.frames)
        self.read_all = read_all and self.selection is not None
        self.options = options.replace(select=None if self.read_all else self.selection)
        self.counts = self._new_counts()

    def _use_pose_file(self, pose_file: Path) -> None:
        """Poses from a TUM file instead of a topic (``ReadSettings.pose_file``)."""
        from alte.io.poses.tum import read_tum

        self.track, self.pose_topic = read_tum(pose_file), str(pose_file)
        self.notes[:] = [n for n in self.notes if n != NO_POSE_NOTE]

    def _new_counts(self) -> ReadCounts:
        track = self.track
        return ReadCounts(pose_samples=len(track) if track else 0,
                          pose_duplicates=track.duplicates if track else 0,
                          pose_reordered=track.reordered if track else 0)

    @property
    def selected(self) -> int:
        """Scans this stream selects (all it reads unless ``read_all``)."""
        return self.scans if self.selection is None else len(self.selection)

    def __iter__(self) -> Iterator[Frame]:
        self.counts = counts = self._new_counts()
        stamps = _StampRange()
        with open_bag(self.path) as reader:
            for frame in _scan_frames(reader, self, counts, stamps):
                counts.frames += 1
                yield frame
        if counts.frames == 0:
            _raise_empty(self, counts, stamps)


@dataclass
class _StampRange:
    """First and last scan stamp seen (for the "different clocks?" message)."""

    low: int | None = None
    high: int | None = None

    def add(self, stamp: int) -> None:
        self.low = stamp if self.low is None else min(self.low, stamp)
        self.high = stamp if self.high is None else max(self.high, stamp)


def _pose_at(track: PoseTrack | None, stamp: int, max_gap_s: float, counts: ReadCounts
             ) -> tuple[NDArray[np.float64], NDArray[np.float64], float, float] | None:
    """The body pose at ``stamp`` (identity without a track); None, counted, when none."""
    if track is None:
        return np.zeros(3), _IDENTITY_Q.copy(), 0.0, 0.0
    samples = track.interpolate([stamp], max_gap_s)
    if samples.outside[0]:
        counts.scans_outside_poses += 1
    elif samples.in_gap[0]:
        counts.scans_in_pose_gap += 1
    if not samples.valid[0]:
        return None
    return (samples.positions[0], samples.quaternions[0], float(samples.offset_s[0]),
            float(samples.angular_rate[0]))


def _scan_frames(reader: AnyReader, stream: FrameStream, counts: ReadCounts,
                 stamps: _StampRange) -> Iterator[Frame]:
    """Stream the cloud topic, yielding posed frames and counting what is dropped."""
    opts, topic = stream.options, stream.cloud_topic
    messages = read_messages(reader, topic, stream.path, opts.select)
    total = stream.scans if opts.select is None else len(opts.select)
    for log_time, msgtype, msg in progress_bar(messages, total=total, desc=topic, unit="scan",
                                       disable=not opts.progress):
        if msg is None:
            counts.scans_skipped += 1
            continue
        counts.scans_read += 1
        stamp = header_stamp(cast(StampedMsg, msg).header, log_time)
        stamps.add(stamp)
        pose = _pose_at(stream.track, stamp, opts.max_gap_s, counts)
        if pose is None:
            continue
        points, times, dropped = _decode(msg, msgtype, topic, opts.return_mode, stamp)
        counts.points_nonfinite += dropped
        if points.shape[0] == 0:
            counts.scans_empty += 1
            continue
        yield Frame(stamp, points, *pose, dropped_points=dropped, times=times)


def _raise_empty(stream: FrameStream, counts: ReadCounts, stamps: _StampRange) -> None:
    """Raise when no scan survived, saying why."""
    where = f"{stream.path}:{stream.cloud_topic}"
    if counts.scans_empty == counts.scans_read or stream.track is None:
        raise BagError(f"{where}: all {counts.scans_read} scans have no usable points")
    track = stream.track
    raise PoseError(
        f"{where}: no scan has a pose from {track.source}: scan stamps {stamps.low}.."
        f"{stamps.high} ns, pose stamps {int(track.stamps[0])}..{int(track.stamps[-1])} ns "
        f"({counts.scans_outside_poses} outside the pose track, "
        f"{counts.scans_in_pose_gap} in gaps > {stream.options.max_gap_s} s, "
        f"{counts.scans_empty} without points): different clocks? Pose the scans by odometry "
        "without it (poses=odometry), or read poses on the scans' clock (pose_topic, "
        "pose_file)", setting=("frame spec.poses", "read.pose_topic", "read.pose_file"))


def read_frames(path: str | Path, options: ReadSettings | None = None, *,
                mount: Mount | None = None) -> FrameSet:
    """Every posed scan of a bag in a list (``options``: :class:`ReadSettings`).

    ``mount`` overrides the bag's ``/tf_static`` body -> sensor transform; with neither
    the mount is identity (noted in ``notes``). Holds the whole bag: the pipeline streams
    a :class:`FrameStream` instead.
    """
    stream = FrameStream(path, options, mount=mount)
    frames = list(stream)
    return FrameSet(frames, stream.mount, stream.counts, stream.cloud_topic, stream.pose_topic,
                    stream.path, stream.notes)
