"""Summarise a bag before reading it: topics, counts, duration, the topics alte would use.

``alte info`` prints this; unlike :func:`alte.io.bags.bag.read_frames`, an ambiguous
auto-detection is reported as a note instead of raised.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from alte.errors import TopicError
from alte.io.bags.reader import (
    CLOUD_TYPES,
    first_frame_id,
    open_bag,
    select_topic,
    static_mount,
    topic_table,
)
from alte.io.poses.pose import POSE_TYPES
from alte.types import Mount

__all__ = ["BagInfo", "inspect_bag"]


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

    def to_dict(self) -> dict[str, object]:
        """JSON-ready form (topics as ``{name: {"type": ..., "count": ...}}``)."""
        mount: dict[str, list[float]] | None = None
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
