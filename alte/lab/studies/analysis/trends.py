"""The thesis' stated trends of tables 5.7-5.12, checked on its numbers and on ours.

Sweeps (5.7-5.9, 5.12): a trend holds when the Spearman rank correlation between parameter
and metric has the stated sign and magnitude >= 0.5. Comparisons (5.10, 5.11): the stated
inequality between the two chosen maps, our times beyond their spreads.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy.stats import spearmanr

from alte.errors import ParameterError
from alte.lab.studies.analysis.tables import (
    _THESIS_COLS,
    _TIMES,
    COMPARISON_TRENDS,
    SWEEP_TRENDS,
    TIME_COLUMN,
    thesis_metrics,
)
from alte.lab.studies.analysis.uncertainty import time_spreads

__all__ = ["trend_table"]


def _rho(x: pd.Series[float], y: pd.Series[float]) -> float:
    if len(x) < 3 or x.nunique() < 2 or y.nunique() < 2:
        return float("nan")
    return float(spearmanr(x, y).statistic)


@dataclass(frozen=True)
class _TrendRow:
    """One row of :func:`trend_table`."""

    table: str
    trend: str
    thesis_rho: float
    ours_rho: float
    holds_in_thesis: bool
    holds_on_ours: bool
    ours_on: str
    ours_time_rho: float


def _sweep_trends(number: int, ours: pd.DataFrame) -> list[_TrendRow]:
    """A time trend is read on our maps' machine-independent cost where they have one
    (``ours_rho``), with the rank correlation of their CPU time beside it."""
    theirs = thesis_metrics(number)
    out = []
    for text, param, metric, sign in SWEEP_TRENDS[number]:
        timed = metric == "elapsed_s" and "cost" in ours and ours["cost"].notna().all()
        r_t = _rho(theirs[param], theirs[metric])
        r_o = _rho(ours[param], ours["cost" if timed else metric])
        r_time = _rho(ours[param], ours[TIME_COLUMN]) if timed and TIME_COLUMN in ours \
            else np.nan
        out.append(_TrendRow(f"5.{number}", text, r_t, r_o, bool(r_t * sign >= 0.5),
                             bool(r_o * sign >= 0.5), "cost" if timed else metric, r_time))
    return out


def _lower(table: pd.DataFrame, column: str, low: str, high: str) -> bool:
    """Every row of mapper ``low`` below every row of ``high`` in ``column`` (a time
    beyond the two rows' spreads)."""
    values = table[column].to_numpy(dtype=np.float64)
    top = bottom = values
    if column in _TIMES and "thesis_" not in column:
        spreads = time_spreads(table)
        top, bottom = values * np.exp(spreads), values * np.exp(-spreads)
    mine = (table["mapper"] == low).to_numpy()
    other = (table["mapper"] == high).to_numpy()
    return bool(top[mine].max() < bottom[other].min())


def _comparison_trends(number: int, table: pd.DataFrame) -> list[_TrendRow]:
    out = []
    for text, low, high, metric in COMPARISON_TRENDS[number]:
        tcol = "thesis_hd_minus_mhd_m" if metric == "hd_minus_mhd_m" else _THESIS_COLS[metric]
        ours = TIME_COLUMN if metric == "elapsed_s" and TIME_COLUMN in table else metric
        out.append(_TrendRow(f"5.{number}", text, np.nan, np.nan, _lower(table, tcol, low, high),
                             _lower(table, ours, low, high), ours, np.nan))
    return out


def trend_table(number: int, table: pd.DataFrame) -> pd.DataFrame:
    """Which of the thesis' stated trends for table 5.``number`` hold, there and on ours.

    Sweeps: a trend holds when the Spearman rank correlation between parameter and metric
    has the stated sign and magnitude >= 0.5 (NaN with fewer than 3 rows); a time trend
    is read on our maps' cost (``ours_on``; ``ours_time_rho``: the CPU time's). Comparisons:
    the stated inequality between the two chosen maps (between every pair of a tie; our
    times beyond their spreads).
    """
    if number in SWEEP_TRENDS:
        return pd.DataFrame(_sweep_trends(number, table))
    if number in COMPARISON_TRENDS:
        return pd.DataFrame(_comparison_trends(number, table))
    raise ParameterError(f"table 5.{number} states no trends; those are 7-12")
