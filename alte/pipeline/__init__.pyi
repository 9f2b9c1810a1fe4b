from .feed import resolve_domain
from .maprun import FrameLog, FrameObserver, MapRun, RunInfo, Snapshot
from .prepare import (
    Merged,
    Registered,
    cache_key,
    merge_frames,
    merged_cloud,
    prepare,
)
from .run import run
from .source import InputKind, Source, StreamCounts, open_input, stream_frames
from .spec import DomainChoice, DomainPolicy, FrameSettings, MapSettings, PoseSource

__all__ = [
    "DomainChoice",
    "DomainPolicy",
    "FrameLog",
    "FrameObserver",
    "FrameSettings",
    "InputKind",
    "MapRun",
    "MapSettings",
    "Merged",
    "PoseSource",
    "Registered",
    "RunInfo",
    "Snapshot",
    "Source",
    "StreamCounts",
    "cache_key",
    "merge_frames",
    "merged_cloud",
    "open_input",
    "prepare",
    "resolve_domain",
    "run",
    "stream_frames",
]
