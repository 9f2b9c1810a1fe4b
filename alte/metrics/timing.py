"""The time of a map as a measured quantity: repeated readings, the least and the spread.

One reading of a mapper's time on a shared machine is one draw from a wide distribution
(other processes take the cores, caches and memory bandwidth). :class:`Timing` holds
the least over ``repeats`` identical runs of the wall seconds inside the mapper calls
(thesis 5.2.1, ``elapsed_s``) and of the CPU seconds of the process during them
(``cpu_s``, every thread; waiting for a core does not count): other load only ever adds
time, so the least reading is the one another run reproduces best (of 3 runs, 0.052 of
log deviation between four whole runs against 0.067 for the median; environment.md).
Each comes with its *spread*: half the natural log of the largest over the smallest
reading, so readings lie within a factor ``exp(spread)`` of their geometric middle
(0.1: about +/-10 %). With one reading the spread is unknown (NaN); the judgement of
time-based claims then uses a floor measured between whole runs
(:data:`alte.lab.studies.analysis.uncertainty.TIME_SPREAD_FLOOR`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from alte.errors import MetricsError

__all__ = ["Timing", "log_spread"]


def log_spread(readings: Sequence[float] | NDArray[np.float64]) -> float:
    """Half the natural log of max/min of positive ``readings``; NaN for fewer than two
    (or any reading <= 0, which a timer of ns resolution gives only for no work)."""
    values = np.asarray(readings, dtype=np.float64)
    if values.size < 2 or not (values > 0).all():
        return float("nan")
    return float(np.log(values.max() / values.min()) / 2)


@dataclass(frozen=True)
class Timing:
    """Least wall and CPU seconds of a map's mapper calls over ``repeats`` runs, with
    their spreads (module docstring)."""

    elapsed_s: float
    cpu_s: float = float("nan")
    elapsed_spread: float = float("nan")
    cpu_spread: float = float("nan")
    repeats: int = 1

    @classmethod
    def of(cls, wall: Sequence[float], cpu: Sequence[float]) -> Timing:
        """The timing of paired readings (one wall and one CPU reading per run): the least
        of each, and their spreads."""
        if len(wall) == 0 or len(wall) != len(cpu):
            raise MetricsError(f"timing: {len(wall)} wall and {len(cpu)} CPU readings; "
                               "expected the same number, at least one")
        return cls(float(np.min(wall)), float(np.min(cpu)), log_spread(wall),
                   log_spread(cpu), len(wall))
