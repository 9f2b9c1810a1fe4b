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
from typing import Any

import numpy as np
from tqdm.auto import tqdm

from alte.errors import BagError, ParameterError, PoseError, TopicError
from alte.io.pointcloud2 import decode_pointcloud2
from alte.io.pose import POSE_TYPES, PoseTrack, header_stamp, pose_records, select_tf_child
from alte.io.reader import (
    CLOUD_TYPES,
    SCAN_TYPE,
    detect_topics,
    first_frame_id,
    open_bag,
    read_messages,
    select_topic,
    static_mount,
    topic_listing,
    topic_table,
)
from alte.types import Frame, Mount

__all__ = ["BagInfo", "FrameSet", "inspect_bag", "read_frames"]

_IDENTITY_Q = np.array([0.0, 0.0, 0.0, 1.0])


@dataclass
class BagInfo:
    """Summary of a bag: its topics and the cloud/pose topics alte would use."""

    path: Path
    topics: dict[str, tuple[str, int]]
    duration_s: float
    start_ns: int
    end_ns: int
    cloud_topic: str | None
    pose_topic: str | None
    frames: int
    mount: Mount | None = None
    notes: list[str] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready form (topics as ``{name: {"type": ..., "count": ...}}``)."""
        mount = None
        if self.mount is not None:
            mount = {
                "translation": self.mount.translation.tolist(),
                "quaternion": self.mount.quaternion.tolist(),
            }
        return {
            "path": str(self.path),
            "topics": {n: {"type": t, "count": c} for n, (t, c) in self.topics.items()},
            "duration_s": self.duration_s,
            "start_ns": self.start_ns,
            "end_ns": self.end_ns,
            "cloud_topic": self.cloud_topic,
            "pose_topic": self.pose_topic,
            "frames": self.frames,
            "mount": mount,
            "notes": list(self.notes),
        }


@dataclass
class FrameSet:
    """The posed scans of a bag plus what was dropped on the way (``counts``, ``notes``)."""

    frames: list[Frame]
    mount: Mount
    counts: dict[str, int]
    cloud_topic: str
    pose_topic: str | None
    path: Path
    notes: list[str] = field(default_factory=list)

    def __len__(self) -> int:
        return len(self.frames)

    def __iter__(self) -> Iterator[Frame]:
        return iter(self.frames)


def inspect_bag(
    path: str | Path, *, cloud_topic: str | None = None, pose_topic: str | None = None
) -> BagInfo:
    """Topics, counts, duration, detected cloud/pose topics and ``/tf_static`` mount.

    Unlike :func:`read_frames`, an ambiguous auto-detection is not an error here:
    the topic is reported as None with a note. Bad overrides still raise.
    """
    bag = Path(path)
    notes: list[str] = []
    with open_bag(bag) as reader:
        topics = topic_table(reader)
        picked: list[str | None] = []
        for override, types, what in (
            (cloud_topic, CLOUD_TYPES, "cloud"),
            (pose_topic, POSE_TYPES, "pose"),
        ):
            try:
                picked.append(select_topic(topics, override, types, what, bag))
            except TopicError as err:
                if override is not None:
                    raise
                notes.append(str(err))
                picked.append(None)
        sensor = first_frame_id(reader, picked[0], bag)
        mount, body = static_mount(reader, sensor, bag)
        if mount is not None:
            notes.append(f"mount from /tf_static {body} -> {sensor}")
        count = int(reader.message_count)
        start, end = (int(reader.start_time), int(reader.end_time)) if count else (0, 0)
    return BagInfo(
        bag,
        topics,
        max(end - start, 0) / 1e9,
        start,
        end,
        picked[0],
        picked[1],
        topics[picked[0]][1] if picked[0] else 0,
        mount,
        notes,
    )


def _read_track(
    reader: Any, topic: str, sensor: str | None, body: str | None, path: Path
) -> PoseTrack:
    """All poses of ``topic`` as a :class:`PoseTrack` (one child frame for ``/tf``)."""
    records = [
        rec
        for log_time, msgtype, msg in read_messages(reader, topic, path)
        for rec in pose_records(msg, msgtype, log_time)
    ]
    source = f"{path}:{topic}"
    if not records:
        raise PoseError(f"{source}: pose topic has no poses")
    if reader.topics[topic].msgtype == "tf2_msgs/msg/TFMessage":
        child = select_tf_child(records, sensor, body, source)
        records = [r for r in records if r[1] == child]
        source = f"{source} ({child})"
    values = np.array([r[3] for r in records], dtype=np.float64)
    stamps = np.array([r[2] for r in records], dtype=np.int64)
    return PoseTrack.from_samples(stamps, values[:, :3], values[:, 3:], source)


def _resolve_mount(static: Mount | None, mount: Mount | None, notes: list[str]) -> Mount:
    """The caller's mount (an explicit override), else ``/tf_static``, else identity (noted)."""
    if mount is not None:
        if static is not None:
            notes.append("mount argument overrides the bag's /tf_static sensor transform")
        return mount
    if static is not None:
        return static
    notes.append("no /tf_static sensor transform and no mount given: identity mount assumed")
    return Mount()


def _decode(msg: Any, msgtype: str, topic: str, return_mode: str) -> tuple[np.ndarray, int]:
    if msgtype == SCAN_TYPE:
        from alte.io.velodyne import decode_velodyne_scan

        return decode_velodyne_scan(msg, return_mode), 0
    return decode_pointcloud2(msg, topic)


def _pose_ok(samples: Any, counts: dict[str, int]) -> bool:
    """Count a scan that gets no pose; True when it has one."""
    if samples.outside[0]:
        counts["scans_outside_poses"] += 1
    elif samples.in_gap[0]:
        counts["scans_in_pose_gap"] += 1
    return bool(samples.valid[0])


def _scan_frames(
    reader: Any, topic: str, track: PoseTrack | None, counts: dict[str, int], opts: dict[str, Any]
) -> Iterator[Frame]:
    """Stream the cloud topic, yielding posed frames and counting what is dropped."""
    messages = read_messages(reader, topic, opts["path"])
    total = reader.topics[topic].msgcount
    for log_time, msgtype, msg in tqdm(
        messages, total=total, desc=topic, unit="scan", disable=not opts["progress"]
    ):
        counts["scans_read"] += 1
        stamp = header_stamp(msg.header, log_time)
        opts["stamps"].append(stamp)
        pose = (np.zeros(3), _IDENTITY_Q.copy(), 0.0, 0.0)
        if track is not None:
            samples = track.interpolate([stamp], opts["max_gap_s"])
            if not _pose_ok(samples, counts):
                continue
            pose = (
                samples.positions[0],
                samples.quaternions[0],
                float(samples.offset_s[0]),
                float(samples.angular_rate[0]),
            )
        points, dropped = _decode(msg, msgtype, topic, opts["return_mode"])
        counts["points_nonfinite"] += dropped
        if points.shape[0] == 0:
            counts["scans_empty"] += 1
            continue
        yield Frame(stamp, points, *pose, dropped_points=dropped)


def _check_frames(frames: list[Frame], counts: dict[str, int], track: Any, opts: dict) -> None:
    """Raise when no scan survived, saying why."""
    if frames:
        return
    where = f"{opts['path']}:{opts['topic']}"
    if counts["scans_empty"] == counts["scans_read"]:
        raise BagError(f"{where}: all {counts['scans_read']} scans have no usable points")
    stamps = opts["stamps"]
    raise PoseError(
        f"{where}: no scan has a pose from {track.source}: scan stamps {min(stamps)}.."
        f"{max(stamps)} ns, pose stamps {int(track.stamps[0])}..{int(track.stamps[-1])} ns "
        f"({counts['scans_outside_poses']} outside the pose track, "
        f"{counts['scans_in_pose_gap']} in gaps > {opts['max_gap_s']} s, "
        f"{counts['scans_empty']} without points): different clocks?"
    )


def read_frames(
    path: str | Path,
    *,
    cloud_topic: str | None = None,
    pose_topic: str | None = None,
    mount: Mount | None = None,
    max_gap_s: float = 0.5,
    return_mode: str = "strongest",
    allow_no_pose: bool = False,
    body_frame: str | None = None,
    progress: bool = False,
) -> FrameSet:
    """Read every scan of a bag as a posed :class:`Frame` (see the module docstring).

    Topics are detected by message type unless given (``pose_topic=""`` forces
    "no pose topic"). Without a pose topic, frames
    get the identity pose only for raw ``VelodyneScan`` packets or with
    ``allow_no_pose=True``. ``body_frame`` picks the child frame of a ``/tf``
    pose topic when ``/tf_static`` does not tell it. ``mount`` overrides the bag's
    ``/tf_static`` body -> sensor transform; with neither the mount is identity
    (noted in ``notes``).
    """
    bag = Path(path)
    if not max_gap_s > 0:
        raise ParameterError(f"max_gap_s={max_gap_s!r} must be > 0")
    notes: list[str] = []
    with open_bag(bag) as reader:
        cloud, pose, track, used_mount = _sources(
            reader,
            bag,
            (cloud_topic, pose_topic, body_frame),
            mount=mount,
            allow_no_pose=allow_no_pose,
            notes=notes,
        )
        counts = _new_counts(track)
        opts = {
            "path": bag,
            "topic": cloud,
            "progress": progress,
            "max_gap_s": max_gap_s,
            "return_mode": return_mode,
            "stamps": [],
        }
        frames = list(_scan_frames(reader, cloud, track, counts, opts))
    _check_frames(frames, counts, track, opts)
    counts["frames"] = len(frames)
    return FrameSet(frames, used_mount, counts, cloud, pose, bag, notes)


def _sources(
    reader: Any,
    bag: Path,
    names: tuple[str | None, str | None, str | None],
    *,
    mount: Mount | None,
    allow_no_pose: bool,
    notes: list[str],
) -> tuple[str, str | None, PoseTrack | None, Mount]:
    """Cloud topic, pose topic, pose track and mount of an open bag (or why not)."""
    topics = topic_table(reader)
    if not topics or not reader.message_count:
        raise BagError(f"{bag} is empty: no messages")
    cloud, pose = detect_topics(topics, bag, names[0], names[1])
    if cloud is None:
        raise TopicError(
            f"{bag}: no cloud topic ({', '.join(CLOUD_TYPES)}); {topic_listing(topics)}"
        )
    if topics[cloud][1] == 0:
        raise BagError(f"{bag}: cloud topic {cloud} has no messages")
    sensor = first_frame_id(reader, cloud, bag)
    static, body = static_mount(reader, sensor, bag)
    used_mount = _resolve_mount(static, mount, notes)
    if pose is not None:
        return cloud, pose, _read_track(reader, pose, sensor, names[2] or body, bag), used_mount
    if topics[cloud][0] != SCAN_TYPE and not allow_no_pose:
        raise TopicError(
            f"{bag}: no pose topic ({', '.join(POSE_TYPES)}) for {cloud}; "
            f"pass allow_no_pose=True to read it unposed; {topic_listing(topics)}"
        )
    notes.append("no pose topic: every frame has the identity pose")
    return cloud, None, None, used_mount


def _new_counts(track: PoseTrack | None) -> dict[str, int]:
    counts = dict.fromkeys(
        (
            "scans_read",
            "scans_outside_poses",
            "scans_in_pose_gap",
            "scans_empty",
            "points_nonfinite",
        ),
        0,
    )
    counts["pose_samples"] = len(track) if track is not None else 0
    counts["pose_duplicates"] = track.duplicates if track is not None else 0
    counts["pose_reordered"] = track.reordered if track is not None else 0
    return counts
