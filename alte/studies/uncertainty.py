"""Confidence intervals over simulation seeds: a seeded percentile bootstrap.

Every compared number of the trade-off analysis is a mean over seeds (one value per
seed, e.g. the MHD difference of two mappers read at one size on one terrain). Its
interval is the percentile bootstrap of that mean (``scipy.stats.bootstrap``), with a
seeded generator so a report is reproducible. With one seed there is no interval: the
bounds equal the value and :attr:`Interval.seeds` says so.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.stats import bootstrap

__all__ = ["CONFIDENCE", "Interval", "bootstrap_ci", "bootstrap_columns"]

#: Confidence level of every interval in the report.
CONFIDENCE = 0.95


@dataclass(frozen=True)
class Interval:
    """Mean over ``seeds`` finite values and its percentile-bootstrap interval."""

    estimate: float
    low: float
    high: float
    seeds: int
    level: float = CONFIDENCE


def bootstrap_ci(values: np.ndarray | list[float], level: float = CONFIDENCE,
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


def bootstrap_columns(values: np.ndarray, level: float = CONFIDENCE, n_resamples: int = 2000,
                      seed: int = 0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
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
