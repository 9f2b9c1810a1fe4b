"""The pipeline: an input and a map specification -> a :class:`MapRun`.

One loop (:func:`~alte.pipeline.feed.map_frames`) serves the CLI, the chapters, the
studies, the sweeps and the bench: frames come either live from the input
(:class:`~alte.pipeline.live.LiveFrames`, one at a time) or from a prepared
registration (:class:`~alte.pipeline.prepare.Registered`, here as
:class:`PreparedFrames`).
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from alte.errors import ParameterError
from alte.mappers import Feed
from alte.pipeline.feed import map_frames
from alte.pipeline.live import LiveFrames
from alte.pipeline.maprun import FrameObserver, MapRun
from alte.pipeline.prepare import Registered, prepare
from alte.pipeline.source import InputKind, Source, StreamCounts, open_input
from alte.pipeline.spec import FrameSettings, MapSettings
from alte.types import Box, RegisteredFrame, Trajectory

__all__ = ["PreparedFrames", "run"]

Input = Registered | Source | str | Path


@dataclass(frozen=True, eq=False)
class PreparedFrames:
    """A prepared registration as the map loop's :class:`~alte.pipeline.feed.FrameInput`."""

    reg: Registered

    @property
    def source(self) -> Source:
        return self.reg.source

    @property
    def spec(self) -> FrameSettings:
        return self.reg.spec

    @property
    def key(self) -> str:
        return self.reg.key

    def bounds(self, feed: Feed) -> Box:
        return Box.around(self.reg.cloud if feed is Feed.BATCH else self.reg.points)

    def frames(self, keep_cloud: bool, progress: bool) -> Iterator[RegisteredFrame]:
        return self.reg.frames()

    def expected(self) -> int:
        return len(self.reg)

    def anchor(self, first: RegisteredFrame) -> NDArray[np.float64]:
        if self.reg.source.kind is InputKind.POINTS:
            return np.asarray(np.median(self.reg.cloud, axis=0))
        return np.asarray(self.reg.trajectory.origins[0])

    def cloud(self) -> NDArray[np.float64] | None:
        return self.reg.cloud

    def counts(self) -> StreamCounts:
        return self.reg.counts

    def trajectory(self, fed: list[RegisteredFrame]) -> Trajectory:
        return self.reg.trajectory


def run(source: Input, spec: MapSettings, frames: FrameSettings | None = None, *,
        cache: Path | None = None, cloud: bool = False, progress: bool = False,
        observer: FrameObserver | None = None) -> MapRun:
    """Map ``source`` as ``spec`` says (module docstring).

    ``source`` is a path, a :class:`Source` or a :class:`Registered` (its frames are
    reused; ``frames`` must then be None). With ``cache`` the registration is kept in
    that folder for the next run; without it the frames are streamed from the input
    (twice when the domain must come from the data) and the merged cloud is kept only
    with ``cloud=True`` (metrics need it) or a batch feed. ``observer`` sees every
    mapped frame and the map after it (:class:`FrameObserver`).
    """
    if isinstance(source, Registered):
        if frames is not None:
            raise ParameterError("run: a prepared registration already fixes its frames")
        return map_frames(PreparedFrames(source), spec, progress=progress, observer=observer)
    src = source if isinstance(source, Source) else open_input(source)
    if cache is not None:
        reg = prepare(src, frames, cache=cache, progress=progress)
        return map_frames(PreparedFrames(reg), spec, progress=progress, observer=observer)
    live = LiveFrames(src, src.resolve(frames or FrameSettings()))
    return map_frames(live, spec, cloud=cloud, progress=progress, observer=observer)

