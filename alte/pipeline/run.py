"""The pipeline: an input and a map specification -> a :class:`MapRun`.

One loop serves the CLI, the chapters, the studies, the sweeps and the bench: frames
come either live from the input (:func:`~alte.pipeline.source.stream_frames`, one at a
time) or from a prepared registration (:class:`~alte.pipeline.prepare.Registered`);
the domain is resolved by one policy; the map is fed frame by frame (``insert``) or
once (``build`` on the merged cloud). Timing follows thesis 5.2.1: ``elapsed_s`` is
the time inside the mapper calls only, ``cpu_s`` the CPU time of the process during them
(every thread; what other load on the machine does not inflate); ``latency_s`` per
frame covers the whole chain (read, register, insert) for the real-time view.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Protocol

import numpy as np
from tqdm.auto import tqdm

from alte import __version__
from alte.errors import ParameterError
from alte.io.pointfiles import local_origin
from alte.mappers import Cells, Domain, DomainUse, Feed, Mapper, make_mapper, mapper_class
from alte.params import Record
from alte.pipeline.prepare import Registered, prepare
from alte.pipeline.source import InputKind, Source, StreamCounts, open_input
from alte.pipeline.spec import DomainPolicy, FrameSpec, MapSpec
from alte.types import Box, RegisteredFrame, Trajectory

__all__ = ["FrameLog", "FrameObserver", "MapRun", "RunInfo", "Snapshot", "local_shift",
           "resolve_domain", "run"]

Input = Registered | Source | str | Path


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
                 shift: np.ndarray) -> None: ...


@dataclass(frozen=True, eq=False)
class FrameLog:
    """Per mapped frame: stamp (ns), points, seconds in the mapper, whole-chain seconds,
    (with snapshots) basis functions after the frame, and CPU seconds in the mapper."""

    stamps: np.ndarray
    points: np.ndarray
    insert_s: np.ndarray
    latency_s: np.ndarray
    basis_functions: np.ndarray
    insert_cpu_s: np.ndarray

    @property
    def times(self) -> np.ndarray:
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
    domain_policy: str
    feed: Feed
    frames: FrameSpec
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
    cloud: np.ndarray | None
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
            "domain_policy": info.domain_policy, "voxel": info.frames.voxel,
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


def resolve_domain(cls: type[Mapper], choice: Domain | DomainPolicy, control: Box | None,
                   data: Callable[[], Box]) -> tuple[Domain | None, str]:
    """The domain a mapper gets and the policy that chose it (one rule for every caller)."""
    if cls.domain_use is DomainUse.UNUSED:
        return None, "none (fixed key space)"
    if isinstance(choice, Domain):
        return choice, "explicit"
    policy = choice
    if policy is DomainPolicy.AUTO:
        policy = DomainPolicy.CONTROL if control is not None else DomainPolicy.DATA
    if policy is DomainPolicy.CONTROL:
        if control is None:
            raise ParameterError("domain policy 'control': the input has no control volume "
                                 "(terrain folders have one); use 'data' or explicit numbers")
        return Domain.over(control), "control"
    return Domain.over(data()), "data"


def local_shift(cls: type[Mapper], first: Callable[[], np.ndarray]) -> np.ndarray:
    """Local origin (1 km grid) for mappers with a key space of their own (UTM-scale data)."""
    if cls.domain_use is not DomainUse.UNUSED:
        return np.zeros(3)
    return local_origin(np.reshape(first(), (-1, 3)))


class Feeder:
    """Feeds frames to a mapper, timing each, keeping snapshots (the run's inner loop)."""

    def __init__(self, mapper: Mapper, spec: MapSpec, feed: Feed, shift: np.ndarray,
                 total: int, *, observer: FrameObserver | None = None) -> None:
        self.mapper, self.feed, self.shift, self.total = mapper, feed, shift, total
        self.observer = observer
        self.keep = set(_snapshot_indices(total, spec.snapshots)) if spec.snapshots else set()
        self.count_basis = spec.snapshots > 0
        self.rows: list[tuple[int, int, float, float, int, float]] = []
        self.snapshots: list[Snapshot] = []
        self.poses: list[RegisteredFrame] = []

    def frame(self, f: RegisteredFrame, waited: float) -> None:
        points, origin = f.points - self.shift, f.origin - self.shift
        cpu, start = time.process_time(), time.perf_counter()
        if self.feed is Feed.FRAMES:
            self.mapper.insert(points, origin)
        spent, cpu = time.perf_counter() - start, time.process_time() - cpu
        basis = self.mapper.basis_functions if self.count_basis else 0
        i = len(self.rows)
        self.rows.append((f.stamp, len(f.points), spent, waited + spent, basis, cpu))
        self.poses.append(RegisteredFrame(f.stamp, np.empty((0, 3)), f.origin, f.position,
                                          f.quaternion))
        if i in self.keep:
            t0 = self.rows[0][0]
            self.snapshots.append(Snapshot(i, (f.stamp - t0) / 1e9, self.mapper.cells(), basis))
        if self.observer is not None:
            self.observer(i, f, self.mapper, self.shift)

    def run(self, frames: Iterator[RegisteredFrame], cloud: Callable[[], np.ndarray | None],
            progress: bool) -> FrameLog:
        """Feed every frame (insert, or record then build once on the merged cloud)."""
        bar = tqdm(_timed(frames), total=self.total or None, desc=self.mapper.name,
                   unit="frame", disable=not progress, leave=False)
        for frame, waited in bar:
            self.frame(frame, waited)
        build = (0.0, 0.0)
        if self.feed is Feed.BATCH:
            points = cloud()
            points = np.empty((0, 3)) if points is None else points - self.shift
            cpu, start = time.process_time(), time.perf_counter()
            self.mapper.build(points)
            build = (time.perf_counter() - start, time.process_time() - cpu)
        return self.log(build)

    def log(self, build: tuple[float, float] = (0.0, 0.0)) -> FrameLog:
        """The frames fed so far; ``build``: wall and CPU seconds of a batch build."""
        arr = np.array(self.rows, dtype=np.float64).reshape(-1, 6)
        insert, latency, cpu = arr[:, 2].copy(), arr[:, 3].copy(), arr[:, 5].copy()
        if self.feed is Feed.BATCH and len(insert):  # the map exists after the build only
            insert[:], cpu[:] = 0.0, 0.0
            insert[-1], cpu[-1] = build
            latency[-1] += build[0]
        stamps = np.array([row[0] for row in self.rows], dtype=np.int64)  # exact ns
        return FrameLog(stamps, arr[:, 1].astype(np.int64), insert, latency,
                        arr[:, 4].astype(np.int64), cpu)


def _snapshot_indices(total: int, snapshots: int) -> list[int]:
    """``snapshots`` frame indices evenly spaced over ``total`` frames, ending at the last."""
    if total < 1:
        return []
    return sorted(set(np.round(np.linspace(0, total - 1, snapshots + 1)[1:]).astype(int)))


def _timed(frames: Iterator[RegisteredFrame]) -> Iterator[tuple[RegisteredFrame, float]]:
    """Each frame with the seconds spent producing it (reading and registering)."""
    while True:
        start = time.perf_counter()
        try:
            frame = next(frames)
        except StopIteration:
            return
        yield frame, time.perf_counter() - start


def _from_registered(reg: Registered, spec: MapSpec, progress: bool,
                     observer: FrameObserver | None = None) -> MapRun:
    cls = mapper_class(spec.mapper)
    feed = spec.feed or cls.default_feed
    points = reg.cloud if feed is Feed.BATCH else reg.points
    domain, policy = resolve_domain(cls, spec.domain, reg.spec.crop,
                                    lambda: Box.around(points))
    mapper = make_mapper(spec.mapper, spec.params, domain=domain)
    first = (lambda: np.median(reg.cloud, axis=0)) if reg.source.kind is InputKind.POINTS \
        else (lambda: reg.trajectory.origins[0])
    shift = local_shift(cls, first)
    start = time.perf_counter()
    feeder = Feeder(mapper, spec, feed, shift, len(reg), observer=observer)
    log = feeder.run(reg.frames(), lambda: reg.cloud, progress)
    info = RunInfo(str(reg.source.path), reg.source.kind, cls.name, mapper.params,
                   mapper.domain if domain is None else domain, policy, feed, reg.spec,
                   _tuple(shift), reg.key)
    return MapRun(mapper, info, log, reg.counts, reg.trajectory, reg.cloud,
                  time.perf_counter() - start, feeder.snapshots)


def _tuple(shift: np.ndarray) -> tuple[float, float, float]:
    return (float(shift[0]), float(shift[1]), float(shift[2]))


def run(source: Input, spec: MapSpec, frames: FrameSpec | None = None, *,
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
        return _from_registered(source, spec, progress, observer)
    src = source if isinstance(source, Source) else open_input(source)
    if cache is not None:
        return _from_registered(prepare(src, frames, cache=cache, progress=progress), spec,
                                progress, observer)
    from alte.pipeline.live import run_live

    return run_live(src, src.resolve(frames or FrameSpec()), spec, cloud=cloud,
                    progress=progress, observer=observer)

