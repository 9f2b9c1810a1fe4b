"""Row 12: odometry and refinement per real scan, beside KISS-ICP's own pipeline.

On the real ``balm_seq`` scans (about 73,000 points each, ``../shared/realdata``) on one
core: alte's default odometry (``odometry_frames``: KISS-ICP behind alte's frame stream,
then each pose re-aligned to the scans around it), its KISS-ICP stage alone
(``window=0``: kiss-icp's own map, so the ratio is the wrapper's cost) and refinement
(``refine_frames`` from the recorded poses) against ``kiss_icp``'s own ``KissICP`` with
its default configuration, fed the same scans in the same run. Times are the process's
CPU time (every thread) per scan (:class:`_Clock`: the window yields a pose 20 scans
late, so per-yield times would be bursty), mean and median over the scans; wall times
and p90 are in the detail. Targets: under 100 ms per scan (a 10 Hz sensor) for odometry
(mean and median) and refinement (mean), the KISS-ICP stage within 1.2x of the peer."""

from __future__ import annotations

import time
from collections.abc import Callable, Iterable, Iterator
from dataclasses import replace
from typing import TYPE_CHECKING, Protocol

import numpy as np

from alte.paths import realdata_dir
from alte.types import Frame, JSONDict, Mount
from bench.core import LIMITS, Context, Result
from bench.timing import one_core

if TYPE_CHECKING:
    from alte.registration.odometry import OdometrySettings, PoseCounts

__all__ = ["pose_speed"]

#: Sensor period (ms): the budget of one scan.
BUDGET_MS = 100.0


def _scans(ctx: Context) -> list[Frame]:
    from alte.io.bags.bag import read_frames

    bag = realdata_dir() / "balm_seq" / "bag"
    limit = 20 if ctx.config.quick else None
    return ctx.memo("balm_frames", lambda: read_frames(bag).frames[:limit])


class _Clock:
    """Per-scan CPU (the process's: every thread it runs) and wall times of a pose stream.

    A scan's time runs from its entry into the stream to the next scan's; the work after
    the last scan entered (its own step and the window's end-of-stream flush) is shared
    evenly by the frames yielded then. So every scan is counted once, and the sum is the
    stream's total: the mean is the total per scan, the median the steady state."""

    def __init__(self) -> None:
        self.cpu: list[float] = []
        self.wall: list[float] = []

    def run(self, frames: list[Frame], stream: Callable[[Iterable[Frame]], Iterator[Frame]],
            ) -> None:
        """Drain ``stream(frames)``, timing each scan (class docstring)."""
        marks: list[tuple[float, float]] = []

        def fed() -> Iterator[Frame]:
            for frame in frames:
                marks.append((time.process_time(), time.perf_counter()))
                yield frame

        late = sum(len(marks) == len(frames) for _ in stream(fed()))
        marks.append((time.process_time(), time.perf_counter()))
        steps = 1e3 * np.diff(np.asarray(marks), axis=0)
        shared = steps[-1] / max(late, 1)
        steps[-1] = 0.0
        steps[len(steps) - max(late, 1):] += shared
        self.cpu.extend(steps[:, 0].tolist())
        self.wall.extend(steps[:, 1].tolist())


def _peer(frames: list[Frame], clock: _Clock) -> None:
    from kiss_icp.config import KISSConfig
    from kiss_icp.kiss_icp import KissICP

    config = KISSConfig()
    config.data.deskew = False  # the scans carry no per-point time
    config.mapping.voxel_size = config.data.max_range / 100.0
    config.registration.max_num_threads = 1
    pipeline = KissICP(config)

    def stream(scans: Iterable[Frame]) -> Iterator[Frame]:
        for frame in scans:
            pipeline.register_frame(frame.points, np.zeros(len(frame.points)))
            yield frame

    clock.run(frames, stream)


class _Poser(Protocol):
    """``odometry_frames`` or ``refine_frames`` as the row calls them."""

    def __call__(self, frames: Iterable[Frame], mount: Mount, *, counts: PoseCounts,
                 params: OdometrySettings) -> Iterator[Frame]: ...


#: The row's streams: name -> (refinement, settings); ``kiss-stage`` is the KISS-ICP stage
#: alone, on kiss-icp's own map (1 m voxel, 20 points a voxel): the peer's configuration.
STREAMS: dict[str, tuple[bool, dict[str, object]]] = {
    "odometry": (False, {}), "kiss-stage": (False, {"window": 0}), "refine": (True, {})}


def _ours(frames: list[Frame], name: str, clock: _Clock) -> None:
    from alte.registration.odometry import (
        OdometrySettings,
        PoseCounts,
        odometry_frames,
        refine_frames,
    )
    refine, settings = STREAMS[name]
    poser: _Poser = refine_frames if refine else odometry_frames
    params = OdometrySettings.parse(settings)
    bare = [replace(f, times=None) for f in frames]
    clock.run(bare, lambda scans: poser(scans, Mount(), counts=PoseCounts(), params=params))


def pose_speed(ctx: Context) -> list[Result]:
    """Row 12 (module docstring); no result without ``../shared/realdata/balm_seq``."""
    if not (realdata_dir() / "balm_seq" / "bag").exists():
        return []
    frames = _scans(ctx)
    clocks = {name: _Clock() for name in ("kiss-icp", *STREAMS)}
    with one_core():
        for _ in range(max(1, ctx.config.repeats // 5)):
            _peer(frames, clocks["kiss-icp"])
            for name in STREAMS:
                _ours(frames, name, clocks[name])
    mean = {k: float(np.mean(c.cpu)) for k, c in clocks.items()}
    median = {k: float(np.median(c.cpu)) for k, c in clocks.items()}
    detail: JSONDict = {
        "scans": len(frames), "points_per_scan": int(np.median([len(f.points) for f in frames])),
        "cpu_ms_mean": mean, "cpu_ms_median": median,
        "wall_ms_median": {k: float(np.median(c.wall)) for k, c in clocks.items()},
        "cpu_ms_p90": {k: float(np.percentile(c.cpu, 90)) for k, c in clocks.items()}}
    scans = f"balm_seq ({len(frames)} scans)"
    odometry = "odometry (KISS-ICP + window) per real scan vs kiss-icp pipeline"
    return [
        Result(12, f"{odometry}, mean, {scans}", mean["odometry"], mean["kiss-icp"], "ms",
               f"< {BUDGET_MS:g} ms", bool(mean["odometry"] < BUDGET_MS), detail),
        Result(12, f"{odometry}, median, {scans}", median["odometry"], median["kiss-icp"],
               "ms", f"< {BUDGET_MS:g} ms", bool(median["odometry"] < BUDGET_MS), detail),
        Result(12, f"odometry's KISS-ICP stage on kiss-icp's map per real scan vs kiss-icp "
               f"pipeline, mean, {scans}", mean["kiss-stage"], mean["kiss-icp"], "ms",
               f"ratio <= {LIMITS[12]:g}",
               bool(mean["kiss-stage"] <= LIMITS[12] * mean["kiss-icp"]), detail),
        Result(12, f"refinement per real scan vs kiss-icp pipeline, mean, {scans}",
               mean["refine"], mean["kiss-icp"], "ms", f"< {BUDGET_MS:g} ms",
               bool(mean["refine"] < BUDGET_MS), detail)]
