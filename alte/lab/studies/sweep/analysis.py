"""Sensitivity of the map metrics to the mapper parameters, from a sweep table.

Thesis 5.2.2 sampled six hand-picked rows per mapper and concluded the mappers are
"sensitive to tuning parameters ... requires further investigation". Over a full
grid, a metric's *main effect* of a parameter is its mean at each level of that
parameter (averaged over the other parameters); the *spread* of those means,
relative to the overall mean, ranks which parameters matter.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

from alte.errors import ParameterError

__all__ = ["main_effects", "mapper_rows", "param_columns", "sensitivity_ranking",
           "sensitivity_table"]


def mapper_rows(table: pd.DataFrame, mapper: str, terrain: str | None = None,
                fixed: Mapping[str, object] | None = None) -> pd.DataFrame:
    """Rows of ``mapper`` (on ``terrain``, with parameters ``fixed``); none is an error."""
    rows = table[table["mapper"] == mapper]
    if terrain is not None:
        rows = rows[rows["terrain"] == terrain]
    for name, value in (fixed or {}).items():
        column = f"p_{name}"
        if column not in rows:
            raise ParameterError(f"sweep table: {mapper} has no parameter {name!r} to fix")
        rows = rows[rows[column] == value]
    if rows.empty:
        where = f" on {terrain}" if terrain else ""
        raise ParameterError(f"sweep table: no {mapper} rows{where} with {dict(fixed or {})}")
    return rows


def param_columns(rows: pd.DataFrame) -> list[str]:
    """The ``p_*`` columns that vary within ``rows`` (the swept parameters)."""
    return [c for c in rows.columns if c.startswith("p_") and rows[c].notna().all()
            and rows[c].nunique() > 1]


def _check(rows: pd.DataFrame, names: Sequence[str]) -> None:
    missing = [n for n in names if n not in rows]
    if missing:
        raise ParameterError(f"sweep table has no column(s) {missing}; columns: "
                             f"{', '.join(rows.columns)}")


def sensitivity_table(table: pd.DataFrame, mapper: str, x: str, y: str, metric: str, *,
                      terrain: str | None = None,
                      fixed: Mapping[str, object] | None = None) -> pd.DataFrame:
    """``metric`` over parameters ``x`` (columns) and ``y`` (index), mean over the others."""
    rows = mapper_rows(table, mapper, terrain, fixed)
    _check(rows, [f"p_{x}", f"p_{y}", metric])
    values = rows[[f"p_{x}", f"p_{y}"]].assign(v=rows[metric].astype(float))
    grid = values.pivot_table(index=f"p_{y}", columns=f"p_{x}", values="v", aggfunc="mean",
                              dropna=False)
    return grid.rename_axis(index=y, columns=x).sort_index().sort_index(axis=1)


def main_effects(table: pd.DataFrame, mapper: str, metric: str, *,
                 terrain: str | None = None) -> pd.DataFrame:
    """Mean ``metric`` at each level of each swept parameter (param, level, mean, runs)."""
    rows = mapper_rows(table, mapper, terrain)
    _check(rows, [metric])
    parts = []
    for column in param_columns(rows):
        grouped = rows.groupby(column)[metric].agg(["mean", "count"]).reset_index()
        grouped.columns = ["level", "mean", "runs"]
        parts.append(grouped.assign(param=column[2:])[["param", "level", "mean", "runs"]])
    if not parts:
        raise ParameterError(f"sweep table: no {mapper} parameter takes more than one value")
    return pd.concat(parts, ignore_index=True)


@dataclass(frozen=True)
class _Spread:
    """One row of :func:`sensitivity_ranking`."""

    mapper: str
    param: str
    metric: str
    spread: float
    relative_spread: float


def _ranking(rows: pd.DataFrame, mapper: str, metric: str) -> list[_Spread]:
    overall = abs(float(np.nanmean(rows[metric].astype(float))))
    out = []
    for column in param_columns(rows):
        means = rows.groupby(column)[metric].mean()
        spread = float(means.max() - means.min())
        out.append(_Spread(mapper, column[2:], metric, spread,
                           spread / overall if overall > 0 else np.nan))
    return out


def sensitivity_ranking(table: pd.DataFrame, metrics: Sequence[str], *,
                        mappers: Sequence[str] | None = None) -> pd.DataFrame:
    """Per mapper, parameter and metric: spread of the main effects (max - min) and that
    spread relative to the metric's mean; largest first within each mapper and metric.

    ``mappers`` defaults to every mapper in ``table`` that sweeps some parameter.
    """
    _check(table, [*metrics, "mapper"])
    names = list(dict.fromkeys(table["mapper"])) if mappers is None else list(mappers)
    out = [entry for name in names for metric in metrics
           for entry in _ranking(mapper_rows(table, name), name, metric)]
    if not out:
        raise ParameterError(f"sweep table: none of {names} sweeps more than one value")
    return (pd.DataFrame(out)
            .sort_values(["mapper", "metric", "relative_spread"], ascending=[True, True, False])
            .reset_index(drop=True))
