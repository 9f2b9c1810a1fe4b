"""The pipeline: an input and a map specification -> a map run.

``run(input, MapSpec(...), FrameSpec(...))`` is the one path from a bag, a terrain
folder or a point file to a map (:mod:`~alte.pipeline.run`); ``prepare`` registers
an input once for several maps (:mod:`~alte.pipeline.prepare`); the specifications
and their policies are in :mod:`~alte.pipeline.spec`.
"""

from alte.pipeline.feed import resolve_domain
from alte.pipeline.maprun import FrameLog, FrameObserver, MapRun, RunInfo, Snapshot
from alte.pipeline.prepare import (
    Merged,
    Registered,
    cache_key,
    merge_frames,
    merged_cloud,
    prepare,
)
from alte.pipeline.run import run
from alte.pipeline.source import InputKind, Source, StreamCounts, open_input, stream_frames
from alte.pipeline.spec import DomainChoice, DomainPolicy, FrameSpec, MapSpec, PoseSource

__all__ = [
    "DomainChoice",
    "DomainPolicy",
    "FrameLog",
    "FrameObserver",
    "FrameSpec",
    "InputKind",
    "MapRun",
    "MapSpec",
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
