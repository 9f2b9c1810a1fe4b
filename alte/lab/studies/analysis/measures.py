"""Per-seed statistics of the claims' checks, measured on a prepared trade-off table.

:func:`measure_check` turns one check (:mod:`alte.lab.studies.thesis.claims.types`) into a
:class:`CheckValues`: one value per (terrain, level, seed), oriented so that a value
above ``threshold`` supports the claim (``relation="better"``), plus what it is and
its unit. Ratios (sizes, times) are natural-log ratios, shown as factors. Terrains
are those of the check's case: the table's ``case`` column when it has one, else
:data:`alte.lab.studies.thesis.numbers.TERRAIN_CASE`.

Time is the one measurement that differs between runs, so a check on the elapsed time
is judged on what does not:

* within one mapper (trends, effects, ...), on the mapper's machine-independent
  ``cost`` (:class:`alte.mappers.Cost`), and measured again on its CPU time as a
  cross-check (:attr:`CheckValues.crosscheck`);
* between mappers (different cost units), on the mapper's CPU time (``map_cpu_s``),
  each value known only within the time's spread: the per-seed ``low`` and ``high`` of
  a comparison (:mod:`alte.lab.studies.analysis.comparisons`, which also reads the thesis' rule with
  its ties).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import fields, replace

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike
from scipy.stats import spearmanr

from alte.errors import ParameterError
from alte.lab.studies.analysis.checks import (
    ELAPSED,
    STAT_COLUMNS,
    CheckValues,
    NoDataError,
    case_rows,
    name,
    unit,
)
from alte.lab.studies.analysis.comparisons import measure_compare
from alte.lab.studies.analysis.tables import TIME_COLUMN
from alte.lab.studies.analysis.tradeoff import label
from alte.lab.studies.sweep.variants import BASE
from alte.lab.studies.thesis.claims.types import (
    Agreement,
    Check,
    Compare,
    Contrast,
    Effect,
    Optimum,
    Summary,
    Trend,
    renamed,
)

__all__ = ["STAT_COLUMNS", "CheckValues", "NoDataError", "measure_check"]


def _rho(xs: ArrayLike, ys: ArrayLike) -> float:
    x, y = np.asarray(xs, dtype=np.float64), np.asarray(ys, dtype=np.float64)
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


def _level_means(group: pd.DataFrame, x: str, metric: str) -> pd.Series[float]:
    return group.groupby(x)[metric].mean().dropna().sort_index()


def _trend(c: Trend, table: pd.DataFrame) -> CheckValues:
    rows = case_rows(table, c.case, (c.mapper,), [c.metric, c.size])
    x = _xcol(rows, c.x)

    def rho(group: pd.DataFrame) -> float:
        if c.largest_half:
            group = group[group[c.size] >= group[c.size].median()]
        means = _level_means(group, x, c.metric)
        return c.sign * _rho(means.index.to_numpy(float), means.to_numpy(float))

    over = "the larger half of " if c.largest_half else ""
    what = (f"Spearman rho of {label(c.metric)} with {label(c.x, False)} over {over}"
            f"{name(c.mapper)}'s maps, times the stated sign ({c.sign:+d})")
    return CheckValues(_per_seed(rows, rho), what, threshold=c.min_rho)


def _optimum(c: Optimum, table: pd.DataFrame) -> CheckValues:
    rows = case_rows(table, c.case, (c.mapper,), [c.metric])
    x = _xcol(rows, c.x)

    def gap(group: pd.DataFrame) -> float:
        means = _level_means(group, x, c.metric)
        if len(means) < 3:
            return float("nan")
        finest = means.iloc[0] if c.finest == "low" else means.iloc[-1]
        return float(finest - means.iloc[1:-1].min())

    what = (f"{label(c.metric)} of {name(c.mapper)} at the finest {c.x} minus the best "
            "interior setting")
    return CheckValues(_per_seed(rows, gap), what, unit(c.metric))


def _spread(group: pd.DataFrame, x: str, metric: str) -> float:
    """How far ``x`` alone moves ``metric``: among settings equal in every other parameter,
    the range of ``metric`` over the levels of ``x``, averaged over those sets, relative
    to the mean of ``metric`` (so rows added off a balanced grid confound nothing)."""
    others = [c for c in group.columns if c.startswith("p_") and c != x
              and group[c].notna().all() and group[c].nunique() > 1]
    means = group.groupby([*others, x], sort=True)[metric].mean().dropna()
    per_set = means.groupby(level=list(range(len(others)))) if others else None
    if per_set is None:
        ranges = np.array([means.max() - means.min()] if len(means) > 1 else [])
    else:
        ranges = (per_set.max() - per_set.min())[per_set.size() > 1].to_numpy(float)
    overall = abs(float(group[metric].mean()))
    if not len(ranges) or not overall > 0:
        return float("nan")
    return float(np.mean(ranges)) / overall


def _effect(c: Effect, table: pd.DataFrame) -> CheckValues:
    rows = case_rows(table, c.case, (c.mapper,), [c.metric])
    x = _xcol(rows, c.param)
    other = _xcol(rows, c.other) if c.other else None
    limit = c.max_spread if c.max_spread is not None else 0.0

    def stat(group: pd.DataFrame) -> float:
        spread = _spread(group, x, c.metric)
        return spread - _spread(group, other, c.metric) if other else limit - spread

    what = (f"relative spread of {label(c.metric)} over {c.param} minus over {c.other}"
            if other else f"{limit:g} minus the relative spread of {label(c.metric)} over "
            f"{c.param}") + f" ({name(c.mapper)})"
    return CheckValues(_per_seed(rows, stat), what)


def _agreement(c: Agreement, table: pd.DataFrame) -> CheckValues:
    columns = [c.metric, c.reference] + ([c.other] if c.other else [])
    rows = case_rows(table, c.case, (c.mapper,), columns)

    def agree(group: pd.DataFrame, metric: str) -> float:
        return c.sign * _rho(group[metric].to_numpy(float), group[c.reference].to_numpy(float))

    def stat(group: pd.DataFrame) -> float:
        mine = agree(group, c.metric)
        return mine - agree(group, c.other) if c.other else c.min_rho - mine

    ref = label(c.reference)
    what = (f"agreement (Spearman rho) with {ref} of {label(c.metric)} minus that of "
            f"{label(c.other)}" if c.other else f"{c.min_rho:g} minus the agreement "
            f"(Spearman rho) of {label(c.metric)} with {ref}") + f", over {name(c.mapper)}'s "
    return CheckValues(_per_seed(rows, stat), what + "settings")


def _aggregate(values: pd.Series[float], agg: str) -> float:
    data = values.to_numpy(float)
    data = data[np.isfinite(data)]
    if data.size == 0:
        return float("nan")
    if agg == "median":
        return float(np.median(data))
    return float(data.std() / data.mean()) if data.size > 1 and data.mean() != 0 else np.nan


def _summary(c: Summary, table: pd.DataFrame) -> CheckValues:
    mappers = (c.better,) + ((c.other,) if c.other else ())
    rows = case_rows(table, c.case, mappers, [c.column])
    sign = 1.0 if c.higher_is_better else -1.0

    def stat(group: pd.DataFrame) -> float:
        mine = _aggregate(group.loc[group["mapper"] == c.better, c.column], c.agg)
        base = (_aggregate(group.loc[group["mapper"] == c.other, c.column], c.agg)
                if c.other else c.threshold)
        return sign * (mine - base)

    agg = "median" if c.agg == "median" else "coefficient of variation"
    first, second = (name(c.better), name(c.other) if c.other else f"{c.threshold:g}")
    if not c.higher_is_better:
        first, second = second, first
    what = f"{agg} of {label(c.column)} over the settings, {first} minus {second}"
    shown = unit(c.column) if c.agg == "median" else ""
    return CheckValues(_per_seed(rows, stat), what, shown)


def _contrast(c: Contrast, table: pd.DataFrame) -> CheckValues:
    """Per terrain and seed: the aggregate in variant ``c.variant`` minus that in the base
    grid (sign-flipped for higher-is-better columns), on the variant's terrains."""
    if "variant" not in table:
        raise NoDataError(f"no ablation rows: variant {c.variant!r} needs the grid's variants")
    rows = case_rows(table, c.case, (c.mapper,), [c.column])
    places = set(rows.loc[rows["variant"] == c.variant, "terrain"])
    if not places:
        raise NoDataError(f"no {name(c.mapper)} rows of variant {c.variant!r} on the {c.case} "
                          "terrains")
    rows = rows[rows["terrain"].isin(places) & rows["variant"].isin((BASE, c.variant))]
    sign = -1.0 if c.higher_is_better else 1.0

    def stat(group: pd.DataFrame) -> float:
        base = _aggregate(group.loc[group["variant"] == BASE, c.column], c.agg)
        other = _aggregate(group.loc[group["variant"] == c.variant, c.column], c.agg)
        return sign * (other - base)

    agg = "median" if c.agg == "median" else "coefficient of variation"
    first, second = (("the grid as specified", c.variant) if c.higher_is_better
                     else (c.variant, "the grid as specified"))
    what = (f"{agg} of {label(c.column)} over {name(c.mapper)}'s settings, {first} minus "
            f"{second}")
    return CheckValues(_per_seed(rows, stat), what, unit(c.column) if c.agg == "median" else "")


#: The checks measured on a table (exact types; the others raise).
_MEASURED = (Compare, Trend, Optimum, Effect, Agreement, Summary, Contrast)


def _measure(check: Check, table: pd.DataFrame) -> CheckValues:
    """The measure of ``check``'s kind on ``table``."""
    match check:
        case Compare():
            values = measure_compare(check, table)
        case Trend():
            values = _trend(check, table)
        case Optimum():
            values = _optimum(check, table)
        case Effect():
            values = _effect(check, table)
        case Agreement():
            values = _agreement(check, table)
        case Summary():
            values = _summary(check, table)
        case Contrast():
            values = _contrast(check, table)
        case _:
            raise ParameterError(f"{type(check).__name__} checks are not measured on a table")
    return values


def _mappers(check: Check) -> tuple[str, ...]:
    if isinstance(check, Summary):
        return (check.better,) + ((check.other,) if check.other else ())
    if isinstance(check, Trend | Optimum | Effect | Agreement):
        return (check.mapper,)
    return ()


def _by_cost(check: Check, table: pd.DataFrame) -> CheckValues:
    """A within-mapper check on the time: judged on the cost where every map of its
    mappers has one, with the CPU time as cross-check (else on the CPU time alone)."""
    timed = renamed(check, ELAPSED, TIME_COLUMN)
    mine = table[table["mapper"].isin(_mappers(check))]
    if "cost" not in mine or mine.empty or mine["cost"].isna().any():
        return replace(_measure(timed, table), time="cpu")
    found = _measure(renamed(check, ELAPSED, "cost"), table)
    units = ", ".join(dict.fromkeys(str(u) for u in mine["cost_unit"].dropna())
                      if "cost_unit" in mine else ())  # the rows carry their cost's unit
    return replace(found, what=f"{found.what}; cost in {units}" if units else found.what,
                   time="cost", crosscheck=_measure(timed, table))


def measure_check(check: Check, table: pd.DataFrame) -> CheckValues:
    """Per-seed statistics of ``check`` on ``table`` (prepared by
    :func:`alte.lab.studies.analysis.tradeoff.prepare`); :class:`NoDataError` when it
    cannot be measured."""
    if type(check) not in _MEASURED:
        raise ParameterError(f"{type(check).__name__} checks are not measured on a table")
    if not isinstance(check, Compare) and any(getattr(check, f.name) == ELAPSED
                                              for f in fields(check)):
        return _by_cost(check, table)
    return _measure(check, table)
