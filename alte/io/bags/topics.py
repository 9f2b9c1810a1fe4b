"""What a bag gives the frame stream: its cloud topic, pose topic and track, and mount.

Topics are detected by message type unless named; the pose track is read whole (one
child frame of ``/tf``); the mount comes from an explicit override, else ``/tf_static``,
else identity (noted). A bag that lacks what is needed is refused with the topics it has.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from rosbags.highlevel import AnyReader

from alte.errors import BagError, PoseError, TopicError
from alte.io.bags.reader import (
    CLOUD_TYPES,
    SCAN_TYPE,
    detect_topics,
    first_frame_id,
    read_messages,
    static_mount,
    topic_listing,
    topic_table,
)
from alte.io.poses.pose import POSE_TYPES, PoseTrack, pose_records, select_tf_child
from alte.types import Mount

__all__ = ["NO_POSE_NOTE", "bag_sources"]

#: The note of a stream read without poses (callers that pose the scans otherwise replace it).
NO_POSE_NOTE = "no pose topic: every frame has the identity pose"


def _read_track(
    reader: AnyReader, topic: str, sensor: str | None, body: str | None, path: Path
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


def bag_sources(
    reader: AnyReader,
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
    notes.append(NO_POSE_NOTE)
    return cloud, None, None, used_mount
