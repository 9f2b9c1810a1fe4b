"""The words of a verdict's evidence: statistics, intervals and criteria as a reader sees them.

Log ratios read as factors (x1.8), differences signed (+0.12) with their unit, levels with
the metric's unit, and each cell of a check as "terrain at level: estimate [low, high]".
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from alte.lab.studies.analysis.measures import CheckValues
from alte.lab.studies.analysis.tradeoff import METRICS
from alte.lab.studies.analysis.uncertainty import TIME_SPREAD_FLOOR

__all__ = ["check_text", "criterion_text", "level_text", "number_text", "time_check_text"]


def number_text(value: float, ratio: bool) -> str:
    """A statistic as text: log ratios as factors (x1.8), others signed (+0.12); an
    unbounded end of an interval (a censored read) as such."""
    if np.isinf(value):
        return "unbounded"
    if not np.isfinite(value):
        return "n/a"
    return f"x{np.exp(value):.3g}" if ratio else f"{value:+.3g}"


def level_text(level: float, column: str) -> str:
    if not np.isfinite(level):
        return ""
    value = f"{level:,.0f}" if abs(level) >= 100 else f"{level:.3g}"
    name, unit = METRICS.get(column, (column, ""))
    return f" at {value} {unit or name}"


def criterion_text(m: CheckValues) -> str:
    unit = f" {m.unit}" if m.unit and not m.ratio else ""
    if m.relation == "undecided":
        return "the interval contains 0"
    if m.relation == "similar":
        return (f"the interval lies within {number_text(-m.band, m.ratio)} .. "
                f"{number_text(m.band, m.ratio)}{unit}")
    return f"the interval lies above {number_text(m.threshold, m.ratio)}{unit}"


def check_text(m: CheckValues, cells: pd.DataFrame) -> str:
    seeds = int(cells["seeds"].max())
    unit = f" {m.unit}" if m.unit and not m.ratio else ""
    parts = []
    columns = ("terrain", "level", "seeds", "estimate", "low", "high")
    for terrain, level, n, est, low, high in zip(*(cells[c].tolist() for c in columns),
                                                 strict=True):
        span = (f" [{number_text(low, m.ratio)}, {number_text(high, m.ratio)}]"
                if n > 1 else " (one seed, no interval)")
        fewer = f" ({n} seeds)" if 1 < n < seeds else ""
        parts.append(f"{terrain}{level_text(level, m.level_name)}: "
                     f"{number_text(est, m.ratio)}{span}{unit}{fewer}")
    return (f"{m.what} ({seeds} seed{'s' if seeds != 1 else ''}; supports the claim where "
            f"{criterion_text(m)}): " + "; ".join(parts))


def time_check_text(m: CheckValues) -> str:
    """How the check's time was judged: on the cost, or on the CPU time within its spread."""
    if m.time == "cpu":
        return f"CPU time, within its spread (>= x{np.exp(TIME_SPREAD_FLOOR):.2f})"
    return "cost" if m.time == "cost" else ""
