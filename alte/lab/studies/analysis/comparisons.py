"""Compare checks: two mappers' values per seed, and the statistic that judges them.

The values are read at the thesis' chosen settings, at the rows the thesis' rule picks
from our sweep (every row of a tie: :func:`alte.lab.studies.analysis.tables.rule_picks`) or off the
Pareto fronts at equal size or equal fidelity. Each seed's value carries bounds: a tie
spans its rows, and a time (the mapper's CPU time, for the thesis' elapsed time) its
spread (:func:`alte.lab.studies.analysis.uncertainty.run_time_spreads`; a time for a fidelity:
:mod:`alte.lab.studies.analysis.time_needed`, where a censored read is an upper bound); the
statistic's bounds follow (log ratio or difference, :func:`oriented`), so a comparison
is decided only where the difference exceeds them.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from alte.lab.studies.analysis.checks import (
    ELAPSED,
    CheckValues,
    NoDataError,
    case_rows,
    name,
    unit,
)
from alte.lab.studies.analysis.tables import TIME_COLUMN, rule_criteria, rule_picks
from alte.lab.studies.analysis.time_needed import time_at_fidelity
from alte.lab.studies.analysis.tradeoff import (
    equal_fidelity,
    equal_size,
    label,
    matching,
    thesis_setting,
)
from alte.lab.studies.analysis.uncertainty import run_time_spreads
from alte.lab.studies.thesis.claims.types import SIZE_COLUMNS, Compare

__all__ = ["RATIO_METRICS", "measure_compare", "oriented"]

#: Metrics compared as log ratios (shown as factors): sizes, times, costs.
RATIO_METRICS = (*SIZE_COLUMNS, ELAPSED, TIME_COLUMN, "cost")


def _bounded(chosen: pd.DataFrame, metric: str) -> tuple[float, float, float]:
    """Mean, least and largest of ``metric`` over ``chosen`` rows (a time within its
    spread)."""
    values = chosen[metric].to_numpy(dtype=np.float64)
    low = high = values
    if metric == TIME_COLUMN:
        spread = run_time_spreads(chosen)
        low, high = values * np.exp(-spread), values * np.exp(spread)
    if not np.isfinite(values).any():
        return np.nan, np.nan, np.nan
    return float(np.nanmean(values)), float(np.nanmin(low)), float(np.nanmax(high))


def _picked(group: pd.DataFrame, c: Compare) -> pd.DataFrame | None:
    """The rows of one mapper, terrain and seed the view reads (None: none can)."""
    if c.at != "rule":
        return group
    criteria = rule_criteria(group)
    if group[list(criteria)].notna().all(axis=1).sum() == 0:
        return None
    return group.iloc[rule_picks(group, criteria)]


def _point_values(rows: pd.DataFrame, c: Compare, metric: str) -> pd.DataFrame:
    """(terrain, level, seed, mapper, value, low, high) at the thesis' settings or the
    rule's pick (a tie: the mean, and bounds over it)."""
    out = []
    for mapper in (c.better, c.other):
        mine = rows[rows["mapper"] == mapper]
        if c.at == "thesis_point":
            setting = thesis_setting(mapper)
            if setting is None:
                raise NoDataError(f"the thesis chose no {mapper} map")
            mine = mine[matching(mine, setting)]
            if mine.empty:
                text = ", ".join(f"{k}={v}" for k, v in setting.items())
                raise NoDataError(f"the table lacks the thesis' setting {mapper} {text}")
        for (terrain, seed), group in mine.groupby(["terrain", "seed"], sort=True):
            chosen = _picked(group, c)
            if chosen is None:
                continue
            value, low, high = _bounded(chosen, metric)
            out.append({"terrain": terrain, "level": np.nan, "seed": seed, "mapper": mapper,
                        "value": value, "low": low, "high": high})
    return pd.DataFrame(out, columns=["terrain", "level", "seed", "mapper", "value", "low",
                                      "high"])


def _read_bounds(reads: pd.DataFrame, table: pd.DataFrame, metric: str) -> pd.DataFrame:
    """Front reads with bounds: a time read off a front moves at most as far (in log) as
    the most uncertain time of the mapper's maps on that terrain and seed."""
    if metric != TIME_COLUMN or reads.empty:
        return reads.assign(low=reads["value"], high=reads["value"])
    worst = table.assign(_spread=run_time_spreads(table)).groupby(
        ["terrain", "seed", "mapper"])["_spread"].max().rename("_u").reset_index()
    out = reads.merge(worst, on=["terrain", "seed", "mapper"], how="left")
    factor = np.exp(out.pop("_u").to_numpy(dtype=np.float64))
    return out.assign(low=out["value"] / factor, high=out["value"] * factor)


def _compare_values(c: Compare, table: pd.DataFrame, metric: str) -> pd.DataFrame:
    pair = (c.better, c.other)
    if c.at == "equal_size":
        reads = equal_size(table, pair, metric, size=c.size, levels=c.levels or None,
                           higher_is_better=c.higher_is_better)
    elif c.at == "equal_fidelity" and metric == TIME_COLUMN:
        return time_at_fidelity(table, pair, metric, fidelity=c.fidelity, levels=c.levels)
    elif c.at == "equal_fidelity":
        reads = equal_fidelity(table, pair, metric, fidelity=c.fidelity,
                               levels=c.levels or None)
    else:
        return _point_values(table, c, metric)
    return _read_bounds(reads, table, metric)


def _compare_what(c: Compare, metric: str, ratio: bool) -> tuple[str, str]:
    sign = "/" if ratio else "minus"
    first, second = ((c.better, c.other) if c.relation == "similar" or
                     (c.higher_is_better and not ratio) else (c.other, c.better))
    head = f"{label(metric)}, {name(first)} {sign} {name(second)}"
    where = {"thesis_point": ("at the thesis' chosen settings", ""),
             "rule": ("at the settings the thesis' rule picks from our sweep", ""),
             "equal_size": (f"at equal {label(c.size, False)}", c.size),
             "equal_fidelity": (f"for equal {label(c.fidelity)}", c.fidelity)}
    text, level = where[c.at]
    return f"{head} {text}", level


def oriented(wide: pd.DataFrame, ratio: bool, sign: float) -> pd.DataFrame:
    """Per seed: the statistic (log ratio or difference, times ``sign``) of the better
    and the other mapper's values, and its bounds from theirs."""
    b, o, lo_b, hi_b, lo_o, hi_o = (wide[k].to_numpy(float) for k in (
        "value_b", "value_o", "low_b", "high_b", "low_o", "high_o"))
    with np.errstate(divide="ignore", invalid="ignore"):
        if ratio:
            value, low, high = np.log(b / o), np.log(lo_b / hi_o), np.log(hi_b / lo_o)
        else:
            value, low, high = b - o, lo_b - hi_o, hi_b - lo_o
    if sign < 0:
        low, high = -high, -low
    return wide[["terrain", "level", "seed"]].assign(value=sign * value, low=low, high=high)


def measure_compare(c: Compare, table: pd.DataFrame) -> CheckValues:
    """Per-seed statistic of ``c`` on a prepared trade-off table (module docstring)."""
    metric = TIME_COLUMN if c.metric == ELAPSED else c.metric
    columns = [metric] + ([c.size] if c.at == "equal_size" else []) + (
        [c.fidelity] if c.at == "equal_fidelity" else [])
    rows = case_rows(table, c.case, (c.better, c.other), columns)
    values = _compare_values(c, rows, metric)
    keys = ["terrain", "level", "seed"]
    wide = values[values["mapper"] == c.better].merge(
        values[values["mapper"] == c.other], on=keys, suffixes=("_b", "_o"))
    wide = wide[wide[["value_b", "value_o"]].notna().all(axis=1)]
    if wide.empty:
        raise NoDataError(f"{name(c.better)} and {name(c.other)} share no terrain and "
                          "size range")
    ratio = metric in RATIO_METRICS
    sign = 1.0 if c.relation == "similar" or c.higher_is_better else -1.0
    stats = oriented(wide, ratio, sign)
    what, level = _compare_what(c, metric, ratio)
    band = float(np.log1p(c.tolerance)) if ratio else c.tolerance
    kind = {"equal_size": "size", "equal_fidelity": "fidelity"}.get(c.at, "")
    timed = metric == TIME_COLUMN
    return CheckValues(stats, what, "x" if ratio else unit(metric), ratio,
                       float(np.log(c.factor)) if ratio else 0.0, c.relation, band, level, kind,
                       "cpu" if timed else "", read_from_times=timed or c.at == "rule")
