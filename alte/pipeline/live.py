"""The live path: frames streamed from the input straight into the mapper.

Memory holds the map, a frame and (when asked) the merged cloud, never the input.
When the domain must come from the data, a first pass over the frames finds their
bounds (streamed too); the frames are then read again for the map.
"""

from __future__ import annotations

import functools
import itertools
import time

import numpy as np

from alte.errors import RegistrationError
from alte.mappers import Feed, make_mapper, mapper_class
from alte.pipeline.run import (
    Feeder,
    FrameObserver,
    MapRun,
    RunInfo,
    local_shift,
    resolve_domain,
)
from alte.pipeline.source import InputKind, Source, StreamCounts, stream_frames
from alte.pipeline.spec import FrameSpec, MapSpec
from alte.registration.grid import GridAccumulator
from alte.registration.register import empty_reason
from alte.types import Box, RegisteredFrame, Trajectory

__all__ = ["bounds_pass", "run_live"]


def bounds_pass(source: Source, spec: FrameSpec) -> Box:
    """The box of every registered frame's points, streamed (the data domain's first pass)."""
    lo, hi = np.full(3, np.inf), np.full(3, -np.inf)
    for frame in stream_frames(source, spec, StreamCounts()):
        lo = np.minimum(lo, frame.points.min(axis=0))
        hi = np.maximum(hi, frame.points.max(axis=0))
    return Box(lo, hi)


class _Cloud:
    """The merged cloud built while frames stream: box-grid cells, or every point."""

    def __init__(self, voxel: float | None, wanted: bool) -> None:
        self.grid = GridAccumulator(voxel) if wanted and voxel is not None else None
        self.parts: list[np.ndarray] | None = [] if wanted and voxel is None else None

    def keep(self, frame: RegisteredFrame) -> RegisteredFrame:
        if self.parts is not None:
            self.parts.append(frame.points)
        return frame

    def points(self) -> np.ndarray | None:
        if self.grid is not None:
            return self.grid.points()
        if self.parts is not None:
            return np.concatenate(self.parts) if self.parts else np.empty((0, 3))
        return None


def run_live(source: Source, frames: FrameSpec, spec: MapSpec, *, cloud: bool = False,
             progress: bool = False, observer: FrameObserver | None = None) -> MapRun:
    """Map ``source`` streaming its frames (``frames`` resolved against the input)."""
    cls = mapper_class(spec.mapper)
    feed = spec.feed or cls.default_feed
    domain, policy = resolve_domain(cls, spec.domain, frames.crop,
                                    lambda: bounds_pass(source, frames))
    mapper = make_mapper(spec.mapper, spec.params, domain=domain)
    counts = StreamCounts()
    merged = _Cloud(frames.voxel, cloud or feed is Feed.BATCH)
    start = time.perf_counter()
    stream = (merged.keep(f) for f in stream_frames(source, frames, counts, merge=merged.grid,
                                                    progress=progress))
    first = next(stream, None)
    if first is None:
        raise RegistrationError(f"{source.path}: {empty_reason(counts.registration)}")
    anchor = first.points if source.kind is InputKind.POINTS else first.origin
    shift = local_shift(cls, lambda: np.median(np.reshape(anchor, (-1, 3)), axis=0))
    cloud_points = functools.cache(merged.points)
    feeder = Feeder(mapper, spec, feed, shift, counts.selected, observer=observer)
    log = feeder.run(itertools.chain([first], stream), cloud_points, progress)
    info = RunInfo(str(source.path), source.kind, cls.name, mapper.params,
                   mapper.domain if domain is None else domain, policy, feed, frames,
                   (float(shift[0]), float(shift[1]), float(shift[2])))
    return MapRun(mapper, info, log, counts, Trajectory.of(feeder.poses), cloud_points(),
                  time.perf_counter() - start, feeder.snapshots)
