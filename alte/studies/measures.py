"""Per-seed statistics of the claims' checks, measured on a prepared trade-off table.

:func:`measure_check` turns one check (:mod:`alte.studies.claims.types`) into a
:class:`CheckValues`: one value per (terrain, level, seed), oriented so that a value
above ``threshold`` supports the claim (``relation="better"``), plus what it is and
its unit. Ratios (sizes, times) are natural-log ratios, shown as factors. Terrains
are those of the check's case: the table's ``case`` column when it has one, else
:data:`alte.studies.thesis.TERRAIN_CASE`.

Time is the one measurement that differs between runs, so a check on the elapsed time
is judged on what does not:

* within one mapper (trends, effects, ...), on the mapper's machine-independent
  ``cost`` (:class:`alte.mappers.Cost`), and measured again on its CPU time as a
  cross-check (:attr:`CheckValues.crosscheck`);
* between mappers (different cost units), on the mapper's CPU time (``map_cpu_s``),
  each value known only within the time's spread
  (:func:`alte.studies.uncertainty.time_spreads`): the per-seed ``low`` and ``high``.

Where the thesis' rule picks (``at="rule"``) and cannot separate rows within the times'
spreads (:func:`alte.studies.tables.rule_picks`), a seed's value is the mean over the
tie and its bounds span the tie.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, fields, replace
from typing import Any

import numpy as np
import pandas as pd
from scipy.stats import spearmanr

from alte.errors import ParameterError
from alte.mappers import mapper_class
from alte.studies.claims.types import (
    SIZE_COLUMNS,
    Agreement,
    Check,
    Compare,
    Effect,
    Optimum,
    Summary,
    Trend,
)
from alte.studies.tables import TIME_COLUMN, rule_criteria, rule_picks
from alte.studies.thesis import TERRAIN_CASE
from alte.studies.tradeoff import (
    MAPPER_NAMES,
    METRICS,
    equal_fidelity,
    equal_size,
    label,
    matching,
    thesis_setting,
)
from alte.studies.uncertainty import time_spreads

__all__ = ["STAT_COLUMNS", "CheckValues", "NoDataError", "measure_check"]

#: Columns of :attr:`CheckValues.stats` (``low`` and ``high`` only where a seed's value is
#: known within bounds: a time, a tie of the rule).
STAT_COLUMNS = ["terrain", "level", "seed", "value"]
#: The time a claim names: the thesis' elapsed time.
ELAPSED = "elapsed_s"
_RATIO_METRICS = (*SIZE_COLUMNS, ELAPSED, TIME_COLUMN, "cost")


class NoDataError(ParameterError):
    """The table cannot measure a check (missing rows, columns or settings)."""


@dataclass(frozen=True)
class CheckValues:
    """Per-seed values of one check and how to read them (see the module docstring).

    ``level_name`` is the column the levels are values of (equal-size or equal-fidelity
    reads), ``level_kind`` ``"size"`` or ``"fidelity"`` (empty without levels).
    ``time``: how a time was read (``"cost"``: judged on the machine-independent cost,
    with ``crosscheck`` the same statistic on the CPU time; ``"cpu"``: the CPU time
    within its spread; empty: no time).
    """

    stats: pd.DataFrame
    what: str
    unit: str = ""
    ratio: bool = False
    threshold: float = 0.0
    relation: str = "better"
    band: float = 0.0
    level_name: str = ""
    level_kind: str = ""
    time: str = ""
    crosscheck: CheckValues | None = None


def _name(mapper: str) -> str:
    return MAPPER_NAMES.get(mapper, mapper)


def _unit(metric: str) -> str:
    return METRICS.get(metric, ("", ""))[1]


def _case_rows(table: pd.DataFrame, case: str, mappers: Sequence[str],
               columns: Sequence[str]) -> pd.DataFrame:
    if "case" in table:
        in_case = table["case"] == case
    else:
        in_case = table["terrain"].map(TERRAIN_CASE) == case
    rows = table[in_case & table["mapper"].isin(mappers)]
    absent = [m for m in mappers if m not in set(rows["mapper"])]
    if absent:
        raise NoDataError(f"no rows of {', '.join(absent)} on the {case} terrains")
    missing = [c for c in columns if c not in rows or not rows[c].notna().any()]
    if missing:
        raise NoDataError(f"no values in column(s) {', '.join(missing)}")
    return rows


def _bounded(chosen: pd.DataFrame, metric: str) -> tuple[float, float, float]:
    """Mean, least and largest of ``metric`` over ``chosen`` rows (a time within its
    spread)."""
    values = chosen[metric].to_numpy(dtype=np.float64)
    low = high = values
    if metric == TIME_COLUMN:
        spread = time_spreads(chosen)
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
    worst = table.assign(_spread=time_spreads(table)).groupby(
        ["terrain", "seed", "mapper"])["_spread"].max().rename("_u").reset_index()
    out = reads.merge(worst, on=["terrain", "seed", "mapper"], how="left")
    factor = np.exp(out.pop("_u").to_numpy(dtype=np.float64))
    return out.assign(low=out["value"] / factor, high=out["value"] * factor)


def _compare_values(c: Compare, table: pd.DataFrame, metric: str) -> pd.DataFrame:
    pair = (c.better, c.other)
    if c.at == "equal_size":
        reads = equal_size(table, pair, metric, size=c.size, levels=c.levels or None,
                           higher_is_better=c.higher_is_better)
    elif c.at == "equal_fidelity":
        reads = equal_fidelity(table, pair, metric, fidelity=c.fidelity,
                               levels=c.levels or None,
                               spread="map_cpu_spread" if metric == TIME_COLUMN else None)
    else:
        return _point_values(table, c, metric)
    return _read_bounds(reads, table, metric)


def _compare_what(c: Compare, metric: str, ratio: bool) -> tuple[str, str]:
    sign = "/" if ratio else "minus"
    first, second = ((c.better, c.other) if c.relation == "similar" or
                     (c.higher_is_better and not ratio) else (c.other, c.better))
    head = f"{label(metric)}, {_name(first)} {sign} {_name(second)}"
    where = {"thesis_point": ("at the thesis' chosen settings", ""),
             "rule": ("at the settings the thesis' rule picks from our sweep", ""),
             "equal_size": (f"at equal {label(c.size, False)}", c.size),
             "equal_fidelity": (f"for equal {label(c.fidelity)}", c.fidelity)}
    text, level = where[c.at]
    return f"{head} {text}", level


def _oriented(wide: pd.DataFrame, ratio: bool, sign: float) -> pd.DataFrame:
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


def _compare(c: Compare, table: pd.DataFrame) -> CheckValues:
    metric = TIME_COLUMN if c.metric == ELAPSED else c.metric
    columns = [metric] + ([c.size] if c.at == "equal_size" else []) + (
        [c.fidelity] if c.at == "equal_fidelity" else [])
    rows = _case_rows(table, c.case, (c.better, c.other), columns)
    values = _compare_values(c, rows, metric)
    keys = ["terrain", "level", "seed"]
    wide = values[values["mapper"] == c.better].merge(
        values[values["mapper"] == c.other], on=keys, suffixes=("_b", "_o"))
    wide = wide[wide[["value_b", "value_o"]].notna().all(axis=1)]
    if wide.empty:
        raise NoDataError(f"{_name(c.better)} and {_name(c.other)} share no terrain and "
                          "size range")
    ratio = metric in _RATIO_METRICS
    sign = 1.0 if c.relation == "similar" or c.higher_is_better else -1.0
    stats = _oriented(wide, ratio, sign)
    what, level = _compare_what(c, metric, ratio)
    band = float(np.log1p(c.tolerance)) if ratio else c.tolerance
    kind = {"equal_size": "size", "equal_fidelity": "fidelity"}.get(c.at, "")
    return CheckValues(stats, what, "x" if ratio else _unit(metric), ratio,
                       float(np.log(c.factor)) if ratio else 0.0, c.relation, band, level, kind,
                       "cpu" if metric == TIME_COLUMN else "")


def _rho(x: np.ndarray, y: np.ndarray) -> float:
    keep = np.isfinite(x) & np.isfinite(y)
    x, y = x[keep], y[keep]
    if x.size < 3 or np.unique(x).size < 2 or np.unique(y).size < 2:
        return float("nan")
    return float(spearmanr(x, y).statistic)


def _per_seed(rows: pd.DataFrame, fn: Callable[[pd.DataFrame], float]) -> pd.DataFrame:
    out = [{"terrain": t, "level": np.nan, "seed": s, "value": fn(g)}
           for (t, s), g in rows.groupby(["terrain", "seed"], sort=True)]
    return pd.DataFrame(out, columns=STAT_COLUMNS)


def _xcol(rows: pd.DataFrame, x: str) -> str:
    if f"p_{x}" in rows:
        return f"p_{x}"
    if x in rows:
        return x
    raise NoDataError(f"the table has no parameter or column {x!r}")


def _level_means(group: pd.DataFrame, x: str, metric: str) -> pd.Series:
    return group.groupby(x)[metric].mean().dropna().sort_index()


def _trend(c: Trend, table: pd.DataFrame) -> CheckValues:
    rows = _case_rows(table, c.case, (c.mapper,), [c.metric, c.size])
    x = _xcol(rows, c.x)

    def rho(group: pd.DataFrame) -> float:
        if c.largest_half:
            group = group[group[c.size] >= group[c.size].median()]
        means = _level_means(group, x, c.metric)
        return c.sign * _rho(means.index.to_numpy(float), means.to_numpy(float))

    over = "the larger half of " if c.largest_half else ""
    what = (f"Spearman rho of {label(c.metric)} with {label(c.x, False)} over {over}"
            f"{_name(c.mapper)}'s maps, times the stated sign ({c.sign:+d})")
    return CheckValues(_per_seed(rows, rho), what, threshold=c.min_rho)


def _optimum(c: Optimum, table: pd.DataFrame) -> CheckValues:
    rows = _case_rows(table, c.case, (c.mapper,), [c.metric])
    x = _xcol(rows, c.x)

    def gap(group: pd.DataFrame) -> float:
        means = _level_means(group, x, c.metric)
        if len(means) < 3:
            return float("nan")
        finest = means.iloc[0] if c.finest == "low" else means.iloc[-1]
        return float(finest - means.iloc[1:-1].min())

    what = (f"{label(c.metric)} of {_name(c.mapper)} at the finest {c.x} minus the best "
            "interior setting")
    return CheckValues(_per_seed(rows, gap), what, _unit(c.metric))


def _spread(group: pd.DataFrame, x: str, metric: str) -> float:
    """How far ``x`` alone moves ``metric``: among settings equal in every other parameter,
    the range of ``metric`` over the levels of ``x``, averaged over those sets, relative
    to the mean of ``metric`` (so rows added off a balanced grid confound nothing)."""
    others = [c for c in group.columns if c.startswith("p_") and c != x
              and group[c].notna().all() and group[c].nunique() > 1]
    sets = group.groupby(others, dropna=False) if others else [((), group)]
    ranges = [float(means.max() - means.min()) for _, part in sets
              if len(means := _level_means(part, x, metric)) > 1]
    overall = abs(float(group[metric].mean()))
    if not ranges or not overall > 0:
        return float("nan")
    return float(np.mean(ranges)) / overall


def _effect(c: Effect, table: pd.DataFrame) -> CheckValues:
    rows = _case_rows(table, c.case, (c.mapper,), [c.metric])
    x = _xcol(rows, c.param)
    other = _xcol(rows, c.other) if c.other else None
    limit = c.max_spread if c.max_spread is not None else 0.0

    def stat(group: pd.DataFrame) -> float:
        spread = _spread(group, x, c.metric)
        return spread - _spread(group, other, c.metric) if other else limit - spread

    what = (f"relative spread of {label(c.metric)} over {c.param} minus over {c.other}"
            if other else f"{limit:g} minus the relative spread of {label(c.metric)} over "
            f"{c.param}") + f" ({_name(c.mapper)})"
    return CheckValues(_per_seed(rows, stat), what)


def _agreement(c: Agreement, table: pd.DataFrame) -> CheckValues:
    columns = [c.metric, c.reference] + ([c.other] if c.other else [])
    rows = _case_rows(table, c.case, (c.mapper,), columns)

    def agree(group: pd.DataFrame, metric: str) -> float:
        return c.sign * _rho(group[metric].to_numpy(float), group[c.reference].to_numpy(float))

    def stat(group: pd.DataFrame) -> float:
        mine = agree(group, c.metric)
        return mine - agree(group, c.other) if c.other else c.min_rho - mine

    ref = label(c.reference)
    what = (f"agreement (Spearman rho) with {ref} of {label(c.metric)} minus that of "
            f"{label(c.other)}" if c.other else f"{c.min_rho:g} minus the agreement "
            f"(Spearman rho) of {label(c.metric)} with {ref}") + f", over {_name(c.mapper)}'s "
    return CheckValues(_per_seed(rows, stat), what + "settings")


def _aggregate(values: pd.Series, agg: str) -> float:
    data = values.to_numpy(float)
    data = data[np.isfinite(data)]
    if data.size == 0:
        return float("nan")
    if agg == "median":
        return float(np.median(data))
    return float(data.std() / data.mean()) if data.size > 1 and data.mean() != 0 else np.nan


def _summary(c: Summary, table: pd.DataFrame) -> CheckValues:
    mappers = (c.better,) + ((c.other,) if c.other else ())
    rows = _case_rows(table, c.case, mappers, [c.column])
    sign = 1.0 if c.higher_is_better else -1.0

    def stat(group: pd.DataFrame) -> float:
        mine = _aggregate(group.loc[group["mapper"] == c.better, c.column], c.agg)
        base = (_aggregate(group.loc[group["mapper"] == c.other, c.column], c.agg)
                if c.other else c.threshold)
        return sign * (mine - base)

    agg = "median" if c.agg == "median" else "coefficient of variation"
    first, second = (_name(c.better), _name(c.other) if c.other else f"{c.threshold:g}")
    if not c.higher_is_better:
        first, second = second, first
    what = f"{agg} of {label(c.column)} over the settings, {first} minus {second}"
    unit = _unit(c.column) if c.agg == "median" else ""
    return CheckValues(_per_seed(rows, stat), what, unit)


_MEASURES: dict[type, Callable[[Any, pd.DataFrame], CheckValues]] = {
    Compare: _compare, Trend: _trend, Optimum: _optimum, Effect: _effect,
    Agreement: _agreement, Summary: _summary}


def _mappers(check: Check) -> tuple[str, ...]:
    if isinstance(check, Summary):
        return (check.better,) + ((check.other,) if check.other else ())
    if isinstance(check, Trend | Optimum | Effect | Agreement):
        return (check.mapper,)
    return ()


def _on(check: Check, column: str) -> Check:
    """``check`` with every field naming the elapsed time naming ``column`` instead."""
    return replace(check, **{f.name: column for f in fields(check)  # type: ignore[arg-type]
                             if getattr(check, f.name) == ELAPSED})


def _by_cost(check: Check, table: pd.DataFrame,
             fn: Callable[[Any, pd.DataFrame], CheckValues]) -> CheckValues:
    """A within-mapper check on the time: judged on the cost where every map of its
    mappers has one, with the CPU time as cross-check (else on the CPU time alone)."""
    timed = _on(check, TIME_COLUMN)
    mine = table[table["mapper"].isin(_mappers(check))]
    if "cost" not in mine or mine.empty or mine["cost"].isna().any():
        return replace(fn(timed, table), time="cpu")
    found = fn(_on(check, "cost"), table)
    units = ", ".join(dict.fromkeys(mapper_class(m).cost_unit.value for m in _mappers(check)))
    return replace(found, what=f"{found.what}; cost in {units}", time="cost",
                   crosscheck=fn(timed, table))


def measure_check(check: Check, table: pd.DataFrame) -> CheckValues:
    """Per-seed statistics of ``check`` on ``table`` (prepared by
    :func:`alte.studies.tradeoff.prepare`); :class:`NoDataError` when it cannot be measured."""
    try:
        fn = _MEASURES[type(check)]
    except KeyError as err:
        raise ParameterError(f"{type(check).__name__} checks are not measured on a table") from err
    if not isinstance(check, Compare) and any(getattr(check, f.name) == ELAPSED
                                              for f in fields(check)):
        return _by_cost(check, table, fn)
    return fn(check, table)
