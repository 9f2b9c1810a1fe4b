"""The map loop: frames, however they arrive, fed into a mapper.

:func:`map_frames` is the one loop of the pipeline. Its frames come from a
:class:`FrameInput`: streamed live from the input (:mod:`~alte.pipeline.live`) or read
back from a prepared registration (:mod:`~alte.pipeline.run`). The domain is resolved by
one policy (:func:`resolve_domain`); the map is fed frame by frame (``insert``) or once
(``build`` on the merged cloud) by a :class:`Feeder`, which times every call.
"""

from __future__ import annotations

import itertools
import time
from collections.abc import Callable, Iterator
from typing import Protocol

import numpy as np
from numpy.typing import NDArray

from alte.errors import ParameterError, RegistrationError
from alte.io.points.pointfiles import local_origin
from alte.mappers import Domain, DomainUse, Feed, Mapper
from alte.pipeline.maprun import FrameLog, FrameObserver, MapRun, RunInfo, Snapshot
from alte.pipeline.source import Source, StreamCounts
from alte.pipeline.spec import DomainChoice, DomainPolicy, FrameSettings, MapSettings
from alte.progress import bar as progress_bar
from alte.registration.register import empty_reason
from alte.types import Box, RegisteredFrame, Trajectory

__all__ = ["Feeder", "FrameInput", "local_shift", "map_frames", "resolve_domain"]


class FrameInput(Protocol):
    """Where the map loop's frames come from (live or prepared), and what it says of them."""

    @property
    def source(self) -> Source:
        """The input."""
        ...

    @property
    def spec(self) -> FrameSettings:
        """How its frames were (or are being) registered."""
        ...

    @property
    def key(self) -> str:
        """The registration cache key ("" when streamed)."""
        ...

    def bounds(self, feed: Feed) -> Box:
        """The box of the points a map with ``feed`` gets (the data domain)."""
        ...

    def frames(self, keep_cloud: bool, progress: bool) -> Iterator[RegisteredFrame]:
        """The frames, once; ``keep_cloud``: keep the merged cloud while they pass."""
        ...

    def expected(self) -> int:
        """How many frames the loop gets (known once the first frame arrived)."""
        ...

    def anchor(self, first: RegisteredFrame) -> NDArray[np.float64]:
        """The point the local origin is chosen near."""
        ...

    def cloud(self) -> NDArray[np.float64] | None:
        """The merged cloud (None when not kept)."""
        ...

    def counts(self) -> StreamCounts:
        """What reading and registration kept and dropped."""
        ...

    def trajectory(self, fed: list[RegisteredFrame]) -> Trajectory:
        """The poses of the frames ``fed`` to the map."""
        ...


def resolve_domain(cls: type[Mapper], choice: Domain | DomainPolicy, control: Box | None,
                   data: Callable[[], Box]) -> tuple[Domain | None, DomainChoice]:
    """The domain a mapper gets and the policy that chose it (one rule for every caller)."""
    if cls.domain_use is DomainUse.UNUSED:
        return None, DomainChoice.NONE
    if isinstance(choice, Domain):
        return choice, DomainChoice.EXPLICIT
    policy = choice
    if policy is DomainPolicy.AUTO:
        policy = DomainPolicy.CONTROL if control is not None else DomainPolicy.DATA
    if policy is DomainPolicy.CONTROL:
        if control is None:
            raise ParameterError("domain policy 'control': the input has no control volume "
                                 "(terrain folders have one); use 'data' or explicit numbers")
        return Domain.over(control), DomainChoice.CONTROL
    return Domain.over(data()), DomainChoice.DATA


def local_shift(cls: type[Mapper], first: Callable[[], NDArray[np.float64]]) -> NDArray[np.float64]:
    """Local origin (1 km grid) for mappers with a key space of their own (UTM-scale data)."""
    if cls.domain_use is not DomainUse.UNUSED:
        return np.zeros(3)
    return local_origin(np.reshape(first(), (-1, 3)))


class Feeder:
    """Feeds frames to a mapper, timing each, keeping snapshots (the run's inner loop)."""

    def __init__(self, mapper: Mapper, spec: MapSettings, feed: Feed, shift: NDArray[np.float64],
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

    def run(self, frames: Iterator[RegisteredFrame],
            cloud: Callable[[], NDArray[np.float64] | None], progress: bool) -> FrameLog:
        """Feed every frame (insert, or record then build once on the merged cloud)."""
        bar = progress_bar(_timed(frames), total=self.total or None, desc=self.mapper.name,
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


def map_frames(frames: FrameInput, spec: MapSettings, *, cloud: bool = False,
               progress: bool = False, observer: FrameObserver | None = None) -> MapRun:
    """Map ``frames`` as ``spec`` says: the one map loop (module docstring)."""
    cls = spec.cls
    feed = spec.feed or cls.default_feed
    domain, policy = resolve_domain(cls, spec.domain, frames.spec.crop,
                                    lambda: frames.bounds(feed))
    mapper = cls(domain, record=spec.record)
    start = time.perf_counter()
    stream = frames.frames(cloud or feed is Feed.BATCH, progress)
    first = next(stream, None)
    if first is None:
        raise RegistrationError(f"{frames.source.path}: "
                                f"{empty_reason(frames.counts().registration)}")
    shift = local_shift(cls, lambda: frames.anchor(first))
    feeder = Feeder(mapper, spec, feed, shift, frames.expected(), observer=observer)
    log = feeder.run(itertools.chain([first], stream), frames.cloud, progress)
    info = RunInfo(str(frames.source.path), frames.source.kind, cls.name, mapper.params,
                   mapper.domain if domain is None else domain, policy, feed, frames.spec,
                   (float(shift[0]), float(shift[1]), float(shift[2])), frames.key)
    return MapRun(mapper, info, log, frames.counts(), frames.trajectory(feeder.poses),
                  frames.cloud(), time.perf_counter() - start, feeder.snapshots)
