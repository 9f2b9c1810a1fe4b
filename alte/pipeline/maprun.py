"""What a map run gives back: the map, how it was made, its per-frame log and counts.

Timing follows thesis 5.2.1: ``elapsed_s`` is the time inside the mapper calls only,
``cpu_s`` the CPU time of the process during them (every thread; what other load on the
machine does not inflate); ``latency_s`` per frame covers the whole chain (read,
register, insert) for the real-time view.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Protocol

import numpy as np
from numpy.typing import NDArray

from alte import __version__
from alte.mappers import Cells, Domain, Feed, Mapper
from alte.params import Record
from alte.pipeline.source import InputKind, StreamCounts
from alte.pipeline.spec import DomainChoice, FrameSettings
from alte.types import RegisteredFrame, Trajectory

__all__ = ["FrameLog", "FrameObserver", "MapRun", "RunInfo", "Snapshot"]


@dataclass(frozen=True)
class Snapshot:
    """The map after frame ``frame`` (0-based) at mission time ``time`` (s)."""

    frame: int
    time: float
    cells: Cells
    basis_functions: int


class FrameObserver(Protocol):
    """Called after each mapped frame (outside the timed mapper call): the frame's index
    among the mapped frames, the frame, the map so far and the local shift its points
    were mapped with (an exporter writes the growing map from here)."""

    def __call__(self, index: int, frame: RegisteredFrame, mapper: Mapper,
                 shift: NDArray[np.float64]) -> None: ...


@dataclass(frozen=True, eq=False)
class FrameLog:
    """Per mapped frame: stamp (ns), points, seconds in the mapper, whole-chain seconds,
    (with snapshots) basis functions after the frame, and CPU seconds in the mapper."""

    stamps: NDArray[np.int64]
    points: NDArray[np.int64]
    insert_s: NDArray[np.float64]
    latency_s: NDArray[np.float64]
    basis_functions: NDArray[np.int64]
    insert_cpu_s: NDArray[np.float64]

    @property
    def times(self) -> NDArray[np.float64]:
        """Seconds since the first frame."""
        return (self.stamps - self.stamps[0]) / 1e9 if len(self.stamps) else np.empty(0)


@dataclass(frozen=True)
class RunInfo:
    """What was run, resolved: the input, mapper, parameters, domain, feed and frames."""

    input: str
    kind: InputKind
    mapper: str
    params: Record
    domain: Domain | None
    domain_policy: DomainChoice
    feed: Feed
    frames: FrameSettings
    local_origin: tuple[float, float, float]
    cache_key: str = ""
    version: str = __version__


@dataclass(eq=False)
class MapRun:
    """A finished map with how it was made (:class:`RunInfo`), per-frame log and counts."""

    mapper: Mapper
    info: RunInfo
    log: FrameLog
    counts: StreamCounts
    trajectory: Trajectory
    cloud: NDArray[np.float64] | None
    wall_s: float
    snapshots: list[Snapshot] = field(default_factory=list)

    @property
    def elapsed_s(self) -> float:
        """Seconds spent inside the mapper calls (thesis 5.2.1)."""
        return float(self.log.insert_s.sum())

    @property
    def cpu_s(self) -> float:
        """CPU seconds of the process inside the mapper calls (all its threads)."""
        return float(self.log.insert_cpu_s.sum())

    def summary(self) -> dict[str, object]:
        """The run as one JSON-ready object (what ``alte map --json`` prints)."""
        counts = self.mapper.cell_counts()
        info = self.info
        return {
            "input": info.input, "input_kind": info.kind.value, "mapper": info.mapper,
            "params": info.params.as_dict(), "feed": info.feed.value,
            "domain": None if info.domain is None else info.domain.as_dict(),
            "domain_policy": info.domain_policy.value, "voxel": info.frames.voxel,
            "pose_source": self.counts.poses.source,
            "odometry": {"method": self.counts.poses.method,
                         "settings": dict(self.counts.poses.settings)}
            if self.counts.poses.method else None,
            "crop": None if info.frames.crop is None else list(info.frames.crop.values()),
            "frames": len(self.log.stamps), "frames_selected": self.counts.selected,
            "points": int(self.log.points.sum()),
            "points_dropped_nonfinite": self.counts.read.points_nonfinite,
            "points_dropped_crop": self.counts.registration.points_dropped_crop,
            "points_outside": int(self.mapper.points_outside),
            "local_origin": list(info.local_origin), "elapsed_s": self.elapsed_s,
            "cpu_s": self.cpu_s, "cost": int(self.mapper.cost),
            "cost_unit": self.mapper.cost_unit.value, "wall_s": self.wall_s,
            "basis_functions": int(self.mapper.basis_functions),
            "cells": counts.cells, "occupied_cells": counts.occupied,
            "memory_bytes": int(self.mapper.memory_bytes), "counts": self.counts.as_dict(),
        }
