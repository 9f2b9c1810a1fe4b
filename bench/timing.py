"""Timing primitives of the benchmark: interleaved medians, per-call latencies, the machine.

Every figure is the median of ``repeats`` runs taken after ``warmup`` discarded ones
(numba compilation, caches, page faults). Ours and the peer run in the same process,
interleaved repeat by repeat with alternating order, so slow drift of a loaded
machine hits both alike.
"""

from __future__ import annotations

import os
import resource
import time
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from alte.errors import ParameterError
from alte.lab.machine import machine_info
from alte.types import JSONDict

__all__ = ["Sample", "fit_exponent", "interleave", "machine_info", "measure", "nlogn_exponent",
           "one_core", "peak_rss_bytes"]


@dataclass(frozen=True)
class Sample:
    """Seconds of each timed repeat (warm-up excluded) and their summary."""

    times: tuple[float, ...]

    @property
    def median(self) -> float:
        """Median seconds over the repeats."""
        return float(np.median(self.times))

    @property
    def spread(self) -> float:
        """Interquartile range over the repeats (seconds)."""
        q1, q3 = np.percentile(self.times, [25, 75])
        return float(q3 - q1)

    def as_dict(self) -> JSONDict:
        """JSON-ready summary."""
        return {"median_s": self.median, "iqr_s": self.spread, "repeats": len(self.times),
                "times_s": list(self.times)}


def check_counts(repeats: int, warmup: int) -> None:
    """``repeats >= 1`` and ``warmup >= 0`` or :class:`ParameterError`."""
    if repeats < 1:
        raise ParameterError(f"bench: repeats={repeats} must be >= 1")
    if warmup < 0:
        raise ParameterError(f"bench: warmup={warmup} must be >= 0")


def interleave(names: Sequence[str], rounds: int) -> Iterable[tuple[int, str]]:
    """``(round, name)`` pairs; the order flips every round (A B, B A, A B, ...)."""
    for r in range(rounds):
        for name in (names if r % 2 == 0 else names[::-1]):
            yield r, name


def measure(funcs: Mapping[str, Callable[[], object]], repeats: int = 5,
            warmup: int = 1) -> dict[str, Sample]:
    """Time every callable ``warmup + repeats`` times, interleaved; keep the last ``repeats``."""
    check_counts(repeats, warmup)
    times: dict[str, list[float]] = {name: [] for name in funcs}
    for r, name in interleave(list(funcs), warmup + repeats):
        start = time.perf_counter()
        funcs[name]()
        elapsed = time.perf_counter() - start
        if r >= warmup:
            times[name].append(elapsed)
    return {name: Sample(tuple(t)) for name, t in times.items()}


def fit_exponent(sizes: Sequence[float] | NDArray[np.float64],
                 seconds: Sequence[float] | NDArray[np.float64]) -> float:
    """Slope of log(seconds) against log(size): the empirical complexity exponent."""
    x, y = np.log(np.asarray(sizes, float)), np.log(np.asarray(seconds, float))
    if np.unique(x).size < 2 or not np.isfinite(y).all():
        raise ParameterError(f"fit_exponent: need >= 2 distinct sizes and finite timings, "
                             f"got {list(sizes)}, {list(seconds)}")
    return float(np.polyfit(x, y, 1)[0])


def nlogn_exponent(sizes: Sequence[float] | NDArray[np.float64]) -> float:
    """The slope :func:`fit_exponent` gives for exact n log n over ``sizes`` (about 1.1)."""
    n = np.asarray(sizes, float)
    return fit_exponent(n, n * np.log(n))


def _threads() -> list[int]:
    try:
        return [int(tid) for tid in os.listdir("/proc/self/task")]
    except OSError:
        return [0]


@contextmanager
def one_core() -> Iterator[int | None]:
    """Run the block on one CPU: every thread of the process (and so every thread started
    in the block) is pinned to the lowest CPU it may use; the masks are restored after.
    Yields that CPU, or None where affinity cannot be set (not Linux)."""
    if not hasattr(os, "sched_setaffinity"):
        yield None
        return
    cpu = min(os.sched_getaffinity(0))
    saved: dict[int, set[int]] = {}
    for tid in _threads():
        try:
            saved[tid] = os.sched_getaffinity(tid)
            os.sched_setaffinity(tid, {cpu})
        except OSError:  # the thread ended meanwhile
            saved.pop(tid, None)
    try:
        yield cpu
    finally:
        for tid, mask in saved.items():
            try:
                os.sched_setaffinity(tid, mask)
            except OSError:
                continue


def peak_rss_bytes() -> int:
    """Peak resident set size of this process so far (bytes; Linux reports KiB)."""
    return int(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss) * 1024
