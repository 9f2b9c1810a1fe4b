"""Confidence intervals over simulation seeds (a seeded percentile bootstrap), and the
measurement uncertainty of a map's time.

Every compared number of the trade-off analysis is a mean over seeds (one value per
seed, e.g. the MHD difference of two mappers read at one size on one terrain). Its
interval is the percentile bootstrap of that mean (``scipy.stats.bootstrap``), with a
seeded generator so a report is reproducible. With one seed there is no interval: the
bounds equal the value and :attr:`Interval.seeds` says so. A value that is itself known
only within bounds (a time, read within its spread; a pick the rule cannot separate
from another) enters as its bounds: :func:`bootstrap_bounds` takes the interval's low
end from the seeds' lower bounds and its high end from their upper bounds.

Times are the one quantity that differs between two runs of the same commit. A map's
time spread (:mod:`alte.metrics.timing`: half the log of max/min over repeated runs) is
taken at least :data:`TIME_SPREAD_FLOOR`, the run-to-run spread of the same maps'
CPU times measured between whole grid runs on a shared machine: a map timed once, or
whose repeats happened to agree, is no better known than that (:func:`time_spreads`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd
from numpy.typing import NDArray
from scipy.stats import bootstrap

__all__ = ["CONFIDENCE", "RUN_TIME_SPREAD", "TIME_SPREAD_FLOOR", "Interval", "bootstrap_bounds",
           "bootstrap_ci", "bootstrap_columns", "run_time_spreads", "time_spreads"]

#: Confidence level of every interval in the report.
CONFIDENCE = 0.95
#: Least spread of a map's time (half the log of max/min; 0.25: within a factor 1.28 of
#: the middle), from the run-to-run differences of the grid's CPU times
#: (docs/explanation/verdicts.md).
TIME_SPREAD_FLOOR = 0.25
#: Spread of a time compared between mappers (a claim on two mappers' times): the
#: run-to-run spread of the same maps' CPU times between four whole chapter 5 grids run at
#: load averages 1 to 16 (95 % of 1,344 maps within exp(2 x 0.16-0.32) between any two),
#: for every map alike: a map's own repeats say how loaded the machine was in that second,
#: and verdicts that followed them moved between runs (docs/explanation/verdicts.md).
RUN_TIME_SPREAD = 0.35


@dataclass(frozen=True)
class Interval:
    """Mean over ``seeds`` finite values and its percentile-bootstrap interval."""

    estimate: float
    low: float
    high: float
    seeds: int
    level: float = CONFIDENCE


def bootstrap_ci(values: NDArray[np.float64] | list[float], level: float = CONFIDENCE,
                 n_resamples: int = 2000, seed: int = 0) -> Interval:
    """Mean of the finite ``values`` with its percentile bootstrap interval at ``level``.

    NaN values (a seed where the quantity is undefined) are dropped; none left gives a
    NaN interval with ``seeds=0``; one left gives a zero-width interval.
    """
    data = np.asarray(values, dtype=np.float64)
    data = data[np.isfinite(data)]
    if data.size == 0:
        return Interval(np.nan, np.nan, np.nan, 0, level)
    mean = float(data.mean())
    if data.size == 1 or np.ptp(data) == 0:
        return Interval(mean, mean, mean, int(data.size), level)
    result = bootstrap((data,), np.mean, n_resamples=n_resamples, confidence_level=level,
                       method="percentile", rng=np.random.default_rng(seed))
    ci = result.confidence_interval
    return Interval(mean, float(ci.low), float(ci.high), int(data.size), level)


def bootstrap_columns(values: NDArray[np.float64], level: float = CONFIDENCE,
                      n_resamples: int = 2000, seed: int = 0,
                      ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Mean and percentile-bootstrap interval of every column of ``values`` (seeds x
    quantities, all finite) in one resampling: the seeds are resampled together, as for
    a curve read at many sizes."""
    data = np.asarray(values, dtype=np.float64)
    mean = data.mean(axis=0)
    if data.shape[0] < 2:
        return mean, mean.copy(), mean.copy()
    result = bootstrap((data,), np.mean, n_resamples=n_resamples, confidence_level=level,
                       method="percentile", axis=0, rng=np.random.default_rng(seed))
    ci = result.confidence_interval
    flat = np.ptp(data, axis=0) == 0  # identical seeds: no spread, no interval
    return mean, np.where(flat, mean, ci.low), np.where(flat, mean, ci.high)


def bootstrap_bounds(values: NDArray[np.float64] | list[float],
                     low: NDArray[np.float64] | list[float],
                     high: NDArray[np.float64] | list[float], *, level: float = CONFIDENCE,
                     n_resamples: int = 2000, seed: int = 0) -> Interval:
    """Mean of the finite ``values`` (over the seeds with both bounds), with an interval
    from the bootstrap interval of the mean of ``low`` (its low end) and of ``high`` (its
    high end): each seed's value known only within [low, high]. An unbounded side (a
    censored read: -inf or +inf) leaves that end of the interval unbounded."""
    data = np.column_stack([np.asarray(a, dtype=np.float64) for a in (values, low, high)])
    data = data[np.isfinite(data[:, 0]) & ~np.isnan(data[:, 1:]).any(axis=1)]
    if data.size == 0:
        return Interval(np.nan, np.nan, np.nan, 0, level)
    ends = []
    for column, side in ((data[:, 1], 0), (data[:, 2], 1)):
        if not np.isfinite(column).all():
            ends.append(-np.inf if side == 0 else np.inf)
            continue
        ci = bootstrap_ci(column, level, n_resamples, seed)
        ends.append(ci.high if side else ci.low)
    return Interval(float(data[:, 0].mean()), float(ends[0]), float(ends[1]), len(data), level)


def time_spreads(table: pd.DataFrame, spread: str = "map_cpu_spread") -> NDArray[np.float64]:
    """Each row's time spread, at least :data:`TIME_SPREAD_FLOOR` (the floor alone where
    the table has no ``spread`` column or a row no value: a time read once)."""
    if spread not in table:
        return np.full(len(table), TIME_SPREAD_FLOOR)
    values = pd.to_numeric(table[spread], errors="coerce").to_numpy(dtype=np.float64)
    return np.asarray(np.fmax(np.nan_to_num(values, nan=0.0), TIME_SPREAD_FLOOR))


def run_time_spreads(table: pd.DataFrame) -> NDArray[np.float64]:
    """:data:`RUN_TIME_SPREAD` for every row: the band within which two mappers' times are
    compared, whatever the maps' own repeats read."""
    return np.full(len(table), RUN_TIME_SPREAD)
