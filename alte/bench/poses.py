"""Row 12: odometry and refinement per real scan, beside KISS-ICP's own pipeline.

On the real ``balm_seq`` scans (about 73,000 points each, ``../shared/realdata``) on one
core: alte's default odometry (``odometry_frames``: KISS-ICP behind alte's frame stream,
then each pose re-aligned to the scans around it), its KISS-ICP stage alone
(``window=0``) and refinement (``refine_frames`` from the recorded poses) against
``kiss_icp``'s own ``KissICP`` with its default configuration, fed the same scans in the
same run. The figure is the mean per-scan time of the pose step (the thread's CPU time
over the whole stream divided by its scans: the window yields a pose 20 scans late, so
per-yield times are bursty; medians and wall times are in the detail). Targets: the
KISS-ICP stage within 1.2x of the peer, and under 100 ms per scan (a 10 Hz sensor) for
odometry and refinement each."""

from __future__ import annotations

import time
from collections.abc import Iterable, Iterator
from dataclasses import replace
from typing import TYPE_CHECKING, Protocol

import numpy as np

from alte.bench.core import LIMITS, Context, Result
from alte.bench.timing import one_core
from alte.paths import realdata_dir
from alte.types import Frame, JSONDict, Mount

if TYPE_CHECKING:
    from alte.registration.odometry import OdometryParams, PoseCounts

__all__ = ["pose_speed"]

#: Sensor period (ms): the budget of one scan.
BUDGET_MS = 100.0


def _scans(ctx: Context) -> list[Frame]:
    from alte.io.bag import read_frames

    bag = realdata_dir() / "balm_seq" / "bag"
    limit = 20 if ctx.config.quick else None
    return ctx.memo("balm_frames", lambda: read_frames(bag, frames=None).frames[:limit])


class _Clock:
    """Per-scan CPU and wall times of a frame stream's steps."""

    def __init__(self) -> None:
        self.cpu: list[float] = []
        self.wall: list[float] = []

    def timed(self, frames: Iterable[Frame]) -> Iterable[Frame]:
        """Time each step of ``frames`` (the work done before the frame is yielded)."""
        it = iter(frames)
        while True:
            cpu, wall = time.thread_time(), time.perf_counter()
            frame = next(it, None)
            if frame is None:
                return
            self.cpu.append(1e3 * (time.thread_time() - cpu))
            self.wall.append(1e3 * (time.perf_counter() - wall))
            yield frame


def _peer(frames: list[Frame], clock: _Clock) -> None:
    from kiss_icp.config import KISSConfig
    from kiss_icp.kiss_icp import KissICP

    config = KISSConfig()
    config.data.deskew = False  # the scans carry no per-point time
    config.mapping.voxel_size = config.data.max_range / 100.0
    config.registration.max_num_threads = 1
    pipeline = KissICP(config)
    for frame in frames:
        cpu, wall = time.thread_time(), time.perf_counter()
        pipeline.register_frame(frame.points, np.zeros(len(frame.points)))
        clock.cpu.append(1e3 * (time.thread_time() - cpu))
        clock.wall.append(1e3 * (time.perf_counter() - wall))


class _Poser(Protocol):
    """``odometry_frames`` or ``refine_frames`` as the row calls them."""

    def __call__(self, frames: Iterable[Frame], mount: Mount, *, counts: PoseCounts,
                 params: OdometryParams) -> Iterator[Frame]: ...


def _ours(frames: list[Frame], refine: bool, clock: _Clock, window: int | None = None) -> None:
    from alte.registration.odometry import (
        OdometryParams,
        PoseCounts,
        odometry_frames,
        refine_frames,
    )
    stream: _Poser = refine_frames if refine else odometry_frames
    bare = [replace(f, times=None) for f in frames]
    params = OdometryParams() if window is None else OdometryParams(window=window)
    for _ in clock.timed(stream(bare, Mount(), counts=PoseCounts(), params=params)):
        pass


def pose_speed(ctx: Context) -> list[Result]:
    """Row 12 (module docstring); no result without ``../shared/realdata/balm_seq``."""
    if not (realdata_dir() / "balm_seq" / "bag").exists():
        return []
    frames = _scans(ctx)
    clocks = {name: _Clock() for name in ("kiss-icp", "odometry", "kiss-stage", "refine")}
    with one_core():
        for _ in range(max(1, ctx.config.repeats // 5)):
            _peer(frames, clocks["kiss-icp"])
            _ours(frames, False, clocks["odometry"])
            _ours(frames, False, clocks["kiss-stage"], window=0)
            _ours(frames, True, clocks["refine"])
    mean = {k: float(np.mean(c.cpu)) for k, c in clocks.items()}
    detail: JSONDict = {
        "scans": len(frames), "points_per_scan": int(np.median([len(f.points) for f in frames])),
        "cpu_ms_mean": mean,
        "cpu_ms_median": {k: float(np.median(c.cpu)) for k, c in clocks.items()},
        "wall_ms_median": {k: float(np.median(c.wall)) for k, c in clocks.items()},
        "cpu_ms_p90": {k: float(np.percentile(c.cpu, 90)) for k, c in clocks.items()}}
    peer, scans = mean["kiss-icp"], f"balm_seq ({len(frames)} scans)"
    return [
        Result(12, f"odometry (KISS-ICP + window) per real scan vs kiss-icp pipeline, {scans}",
               mean["odometry"], peer, "ms", f"< {BUDGET_MS:g} ms",
               bool(mean["odometry"] < BUDGET_MS), detail),
        Result(12, f"odometry's KISS-ICP stage per real scan vs kiss-icp pipeline, {scans}",
               mean["kiss-stage"], peer, "ms", f"ratio <= {LIMITS[12]:g}, < {BUDGET_MS:g} ms",
               bool(mean["kiss-stage"] <= LIMITS[12] * peer and mean["kiss-stage"] < BUDGET_MS),
               detail),
        Result(12, f"refinement per real scan vs kiss-icp pipeline, {scans}", mean["refine"],
               peer, "ms", f"< {BUDGET_MS:g} ms", bool(mean["refine"] < BUDGET_MS), detail)]
