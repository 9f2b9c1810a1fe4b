"""The live path: frames streamed from the input straight into the map loop.

Memory holds the map, a frame and (when asked) the merged cloud, never the input.
When the domain must come from the data, a first pass over the frames finds their
bounds (streamed too); the frames are then read again for the map.
"""

from __future__ import annotations

import functools
from collections.abc import Iterator

import numpy as np
from numpy.typing import NDArray

from alte.mappers import Feed
from alte.pipeline.source import InputKind, Source, StreamCounts, stream_frames
from alte.pipeline.spec import FrameSettings
from alte.registration.grid import GridAccumulator
from alte.types import Box, RegisteredFrame, Trajectory

__all__ = ["LiveFrames", "bounds_pass"]


def bounds_pass(source: Source, spec: FrameSettings) -> Box:
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
        self.parts: list[NDArray[np.float64]] | None = [] if wanted and voxel is None else None

    def keep(self, frame: RegisteredFrame) -> RegisteredFrame:
        if self.parts is not None:
            self.parts.append(frame.points)
        return frame

    def points(self) -> NDArray[np.float64] | None:
        if self.grid is not None:
            return self.grid.points()
        if self.parts is not None:
            return np.concatenate(self.parts) if self.parts else np.empty((0, 3))
        return None


class LiveFrames:
    """An input's frames streamed once into the map loop (a
    :class:`~alte.pipeline.feed.FrameInput`; ``spec`` resolved against the input)."""

    key = ""

    def __init__(self, source: Source, spec: FrameSettings) -> None:
        self.source, self.spec = source, spec
        self._counts = StreamCounts()
        self._merged = _Cloud(spec.voxel, False)
        self.cloud = functools.cache(self._cloud)

    def bounds(self, feed: Feed) -> Box:
        return bounds_pass(self.source, self.spec)

    def frames(self, keep_cloud: bool, progress: bool) -> Iterator[RegisteredFrame]:
        self._merged = merged = _Cloud(self.spec.voxel, keep_cloud)
        return (merged.keep(f) for f in stream_frames(self.source, self.spec, self._counts,
                                                      merge=merged.grid, progress=progress))

    def expected(self) -> int:
        return self._counts.selected

    def anchor(self, first: RegisteredFrame) -> NDArray[np.float64]:
        points = first.points if self.source.kind is InputKind.POINTS else first.origin
        return np.asarray(np.median(np.reshape(points, (-1, 3)), axis=0))

    def _cloud(self) -> NDArray[np.float64] | None:
        return self._merged.points()

    def counts(self) -> StreamCounts:
        return self._counts

    def trajectory(self, fed: list[RegisteredFrame]) -> Trajectory:
        return Trajectory.of(fed)
