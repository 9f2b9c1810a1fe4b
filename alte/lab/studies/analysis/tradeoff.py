"""Trade-off tables: map size against fidelity and time, per mapper, terrain and seed.

A trade-off table has one row per (terrain, mapper, parameter setting, seed) and at
least the columns of :data:`REQUIRED_COLUMNS` (``params``: the setting as JSON or
``"k=v, k=v"`` text; parameters may also come as ``p_<name>`` columns, as
``alte sweep`` writes them). :func:`prepare` checks it and adds derived columns.

A mapper's *Pareto front* on one terrain and seed is the set of its maps that no other
of its maps beats in both size and error (the lower-left envelope, x = size, y =
error). Fronts are read *at equal size* (the error at a given size, interpolated
linearly in log10 size between front points) and *at equal fidelity* (the size needed
for a given error, interpolated the same way); outside a front's range a read is NaN,
never extrapolated. Without explicit levels, three are chosen inside the range every
front of the compared mappers covers on that terrain.
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from alte.errors import ParameterError
from alte.lab.studies.analysis.uncertainty import CONFIDENCE, bootstrap_ci
from alte.lab.studies.thesis.numbers import COMPARISONS, SWEEPS
from alte.params import key_values

__all__ = ["METRICS", "OPTIONAL_COLUMNS", "REQUIRED_COLUMNS", "equal_fidelity",
           "equal_size", "fronts", "interval_table", "label", "matching", "pareto_front",
           "parse_params", "prepare", "read_at_size", "size_for_fidelity", "thesis_setting"]

#: Sizes or fidelities to read fronts at.
Levels = Sequence[float] | NDArray[np.float64]
#: Columns every trade-off table must have.
REQUIRED_COLUMNS = ("terrain", "mapper", "params", "seed", "basis_functions", "occupied_cells",
                    "memory_bytes", "elapsed_s", "mhd_m", "hd_m", "accuracy_mean_m",
                    "completeness")
#: Columns some claims need (2D maps: height RMSE; cell-size spread; directed MHDs; the
#: time as measured, :class:`alte.metrics.timing.Timing`, and the mapper's cost).
OPTIONAL_COLUMNS = ("mh_ab_m", "mh_ba_m", "height_rmse_m", "size_octaves", "hd_minus_mhd_m",
                    "elapsed_spread", "map_cpu_s", "map_cpu_spread", "time_repeats", "cost",
                    "cost_unit")


def mapper_title(name: str) -> str:
    """The display name of a mapper by its name in a table: its class's ``title``, found by
    the registry (:func:`alte.mappers.registry.title`; imported on first use, the mappers'
    kernels being heavy), or the name itself for a mapper this process does not know."""
    from alte.mappers import registry

    return registry.title(name)

#: Metric -> (label, unit) for text, tables and axes.
METRICS: dict[str, tuple[str, str]] = {
    "basis_functions": ("basis functions", ""), "occupied_cells": ("occupied cells", ""),
    "memory_bytes": ("memory", "B"), "elapsed_s": ("mapping time", "s"),
    "map_cpu_s": ("mapping CPU time", "s"), "cost": ("mapping cost", ""),
    "mhd_m": ("MHD", "m"), "hd_m": ("HD", "m"), "hd_minus_mhd_m": ("HD - MHD", "m"),
    "mh_ab_m": ("MHD cloud to map", "m"), "mh_ba_m": ("MHD map to cloud", "m"),
    "accuracy_mean_m": ("mean accuracy", "m"), "completeness": ("completeness", ""),
    "height_rmse_m": ("height RMSE", "m"), "size_octaves": ("cell-size octaves", ""),
    "free_share": ("share of free cells", ""),
    "obstacle_recall": ("obstacle recall", ""), "obstacle_precision": ("obstacle precision", ""),
    "obstacle_height_error_m": ("obstacle height error", "m"),
}


def label(metric: str, unit: bool = True) -> str:
    """``"MHD [m]"`` for ``"mhd_m"``; unknown names are returned as they are."""
    name, units = METRICS.get(metric, (metric, ""))
    return f"{name} [{units}]" if unit and units else name


def parse_params(text: object) -> dict[str, object]:
    """A parameter setting from JSON (``{"kappa": 0.1}``) or ``"kappa=0.1, max_res=5"``."""
    if isinstance(text, dict):
        return dict(text)
    raw = str(text).strip()
    if raw.startswith("{"):
        try:
            return dict(json.loads(raw))
        except ValueError as err:
            raise ParameterError(f"trade-off table: params {raw!r} is not JSON") from err
    try:
        pairs = key_values(filter(None, (p.strip() for p in raw.split(","))))
    except ParameterError as err:
        raise ParameterError(f"trade-off table: params {raw!r}: expected k=v, k=v") from err
    out: dict[str, object] = {}
    for key, value in pairs.items():
        try:
            out[key] = float(value)
        except ValueError:
            out[key] = value
    return out


def prepare(table: pd.DataFrame) -> pd.DataFrame:
    """Check the trade-off schema; add ``p_*`` parameter columns (parsed from ``params``
    when absent), ``hd_minus_mhd_m`` and ``free_share`` (1 - occupied/basis functions).
    Rows of ``alte sweep`` (:func:`alte.lab.studies.sweep.load_results`) name the setting
    ``params_json``; it serves as ``params``. A table without the CPU time of its maps
    (older runs, other tools) gets ``map_cpu_s`` = ``elapsed_s`` with no spread, and
    ``cost`` NaN (not measured)."""
    if "params" not in table.columns and "params_json" in table.columns:  # `alte sweep` rows
        table = table.assign(params=table["params_json"])
    missing = [c for c in REQUIRED_COLUMNS if c not in table.columns]
    if missing:
        raise ParameterError(f"trade-off table lacks column(s) {', '.join(missing)}; it needs "
                             f"{', '.join(REQUIRED_COLUMNS)}")
    out = table.copy()
    if not any(str(c).startswith("p_") for c in out.columns):
        parsed = pd.DataFrame([parse_params(p) for p in out["params"]], index=out.index)
        out = out.join(parsed.add_prefix("p_"))
    if "hd_minus_mhd_m" not in out:
        out["hd_minus_mhd_m"] = out["hd_m"] - out["mhd_m"]
    if "map_cpu_s" not in out:
        out["map_cpu_s"], out["map_cpu_spread"] = out["elapsed_s"], np.nan
    if "cost" not in out:
        out["cost"] = np.nan
    basis = out["basis_functions"].astype(float)
    out["free_share"] = 1.0 - out["occupied_cells"].astype(float) / basis.where(basis > 0)
    return out


def thesis_setting(mapper: str) -> dict[str, float] | None:
    """The parameters of ``mapper``'s map the thesis chose (tables 5.10-5.11), if any."""
    for chosen in COMPARISONS.values():
        if mapper in chosen:
            number, row = chosen[mapper]
            return dict(SWEEPS[number]["rows"][row][0])
    return None


def matching(rows: pd.DataFrame, setting: Mapping[str, float]) -> pd.Series[bool]:
    """Which ``rows`` (with ``p_*`` columns) have every parameter of ``setting``."""
    match = pd.Series(True, index=rows.index)
    for key, value in setting.items():
        column = f"p_{key}"
        if column not in rows:
            return pd.Series(False, index=rows.index)
        match &= np.isclose(pd.to_numeric(rows[column], errors="coerce"), float(value))
    return match


def pareto_front(x: NDArray[np.float64], y: NDArray[np.float64]) -> NDArray[np.intp]:
    """Indices of the lower-left Pareto front of points (x, y), sorted by x.

    A point is on the front when no other point has both x and y no larger (one
    strictly smaller); non-finite points are never on it.
    """
    x, y = np.asarray(x, dtype=np.float64), np.asarray(y, dtype=np.float64)
    valid = np.flatnonzero(np.isfinite(x) & np.isfinite(y))
    if valid.size == 0:
        return valid
    order = valid[np.lexsort((y[valid], x[valid]))]
    ys = y[order]
    keep = np.ones(ys.size, dtype=bool)
    keep[1:] = ys[1:] < np.minimum.accumulate(ys)[:-1]
    return order[keep]


def read_at_size(xs: NDArray[np.float64], ys: NDArray[np.float64], levels: Levels,
                 x_max: float | None = None) -> NDArray[np.float64]:
    """The front's error at each size in ``levels``: linear in log10 size between front
    points, flat from the last front point up to ``x_max`` (the largest map made: a
    larger map did no better), NaN outside."""
    if len(xs) == 0:
        return np.full(len(levels), np.nan)
    if x_max is not None and x_max > xs[-1]:
        xs, ys = np.append(xs, x_max), np.append(ys, ys[-1])
    return np.asarray(np.interp(np.log10(np.asarray(levels, dtype=np.float64)), np.log10(xs),
                                ys, left=np.nan, right=np.nan), dtype=np.float64)


def size_for_fidelity(xs: NDArray[np.float64], ys: NDArray[np.float64],
                      levels: Levels) -> NDArray[np.float64]:
    """The size the front needs to reach each error in ``levels`` (linear in log10 size
    between front points); NaN outside the front's error range (a level its smallest map
    already beats is censored: a smaller map might too)."""
    if len(xs) == 0:
        return np.full(len(levels), np.nan)
    logs = np.interp(np.asarray(levels, dtype=np.float64), ys[::-1], np.log10(xs)[::-1],
                     left=np.nan, right=np.nan)
    return np.asarray(np.power(10.0, logs), dtype=np.float64)


def fronts(table: pd.DataFrame, size: str = "basis_functions", metric: str = "mhd_m",
           higher_is_better: bool = False) -> pd.DataFrame:
    """Every map as (terrain, mapper, seed, params, x, y, on_front); x = size, y = metric."""
    _need(table, [size, metric])
    parts = []
    for (terrain, mapper, seed), rows in table.groupby(["terrain", "mapper", "seed"], sort=True):
        x = rows[size].to_numpy(dtype=np.float64)
        y = rows[metric].to_numpy(dtype=np.float64)
        on = np.zeros(len(rows), dtype=bool)
        on[pareto_front(np.where(x > 0, x, np.nan), -y if higher_is_better else y)] = True
        parts.append(pd.DataFrame({"terrain": terrain, "mapper": mapper, "seed": seed,
                                   "params": rows["params"].astype(str).to_numpy(), "x": x,
                                   "y": y, "on_front": on}))
    columns = ["terrain", "mapper", "seed", "params", "x", "y", "on_front"]
    return pd.concat(parts, ignore_index=True) if parts else pd.DataFrame(columns=columns)


def _need(table: pd.DataFrame, columns: Sequence[str]) -> None:
    missing = [c for c in columns if c not in table.columns]
    if missing:
        raise ParameterError(f"trade-off table has no column(s) {', '.join(missing)}")


def _levels(lo: float, hi: float, log: bool) -> list[float]:
    """Three levels at 20/50/80 % of [lo, hi] (in log space for sizes), 2 significant digits."""
    if not (np.isfinite(lo) and np.isfinite(hi)) or lo > hi:
        return []
    a, b = (np.log10(lo), np.log10(hi)) if log else (lo, hi)
    raw = [a + f * (b - a) for f in (0.2, 0.5, 0.8)]
    values = [10**v if log else v for v in raw]
    rounded = [float(f"{v:.2g}") for v in values]
    return sorted({r if lo <= r <= hi else v for r, v in zip(rounded, values, strict=True)})


Curve = tuple[NDArray[np.float64], NDArray[np.float64], float]


def _curves(part: pd.DataFrame, x: str, y: str, sign: float) -> dict[tuple[str, object], Curve]:
    """Each (mapper, seed)'s front on one terrain (y times ``sign``) and its largest x."""
    curves: dict[tuple[str, object], Curve] = {}
    for (mapper, seed), group in part.groupby(["mapper", "seed"], sort=True):
        xv = group[x].to_numpy(dtype=np.float64)
        yv = sign * group[y].to_numpy(dtype=np.float64)
        idx = pareto_front(np.where(xv > 0, xv, np.nan), yv)
        if idx.size:
            curves[(str(mapper), seed)] = (xv[idx], yv[idx], float(np.nanmax(xv)))
    return curves


def _span(curves: Sequence[Curve], by_size: bool) -> tuple[float, float]:
    """The range of sizes (signed errors) every curve can be read at."""
    if by_size:
        return max(float(c[0][0]) for c in curves), min(c[2] for c in curves)
    return max(float(c[1][-1]) for c in curves), min(float(c[1][0]) for c in curves)


def _front_reads(table: pd.DataFrame, mappers: Sequence[str], axes: tuple[str, str], *,
                 sign: float, levels: Levels | None, by_size: bool) -> pd.DataFrame:
    rows = []
    for terrain, part in table[table["mapper"].isin(mappers)].groupby("terrain", sort=True):
        curves = _curves(part, *axes, sign)
        if {m for m, _ in curves} != set(mappers):
            continue
        lo, hi = _span(list(curves.values()), by_size)
        if not by_size:
            lo, hi = sorted((sign * lo, sign * hi))
        wanted = list(levels) if levels is not None and len(levels) else _levels(lo, hi,
                                                                               log=by_size)
        at = np.asarray(wanted, dtype=np.float64)
        for (mapper, seed), (xs, ys, x_max) in curves.items():
            values = (sign * read_at_size(xs, ys, at, x_max) if by_size
                      else size_for_fidelity(xs, ys, sign * at))
            rows += [{"terrain": terrain, "seed": seed, "level": lv, "mapper": mapper,
                      "value": v} for lv, v in zip(wanted, values, strict=True)]
    return pd.DataFrame(rows, columns=["terrain", "seed", "level", "mapper", "value"])


def equal_size(table: pd.DataFrame, mappers: Sequence[str], metric: str = "mhd_m", *,
               size: str = "basis_functions", levels: Levels | None = None,
               higher_is_better: bool = False) -> pd.DataFrame:
    """``metric`` read off each mapper's front at equal ``size`` levels, per terrain and seed.

    Returns (terrain, seed, level, mapper, value); terrains lacking a mapper are left out.
    """
    _need(table, ["terrain", "mapper", "seed", size, metric])
    sign = -1.0 if higher_is_better else 1.0
    return _front_reads(table, mappers, (size, metric), sign=sign, levels=levels, by_size=True)


def equal_fidelity(table: pd.DataFrame, mappers: Sequence[str],
                   metric: str = "basis_functions", *, fidelity: str = "mhd_m",
                   levels: Levels | None = None,
                   higher_is_better: bool = False) -> pd.DataFrame:
    """The ``metric`` (a size or the time) each mapper needs to reach ``fidelity`` levels,
    read off its (metric, fidelity) front; same columns as :func:`equal_size`."""
    _need(table, ["terrain", "mapper", "seed", metric, fidelity])
    sign = -1.0 if higher_is_better else 1.0
    return _front_reads(table, mappers, (metric, fidelity), sign=sign, levels=levels,
                        by_size=False)


def interval_table(reads: pd.DataFrame, level: float = CONFIDENCE, seed: int = 0) -> pd.DataFrame:
    """Mean over seeds of each (terrain, level, mapper) read with its bootstrap interval."""
    rows = []
    for (terrain, at, mapper), group in reads.groupby(["terrain", "level", "mapper"], sort=True):
        ci = bootstrap_ci(group["value"].to_numpy(), level=level, seed=seed)
        rows.append({"terrain": terrain, "level": at, "mapper": mapper, "mean": ci.estimate,
                     "low": ci.low, "high": ci.high, "seeds": ci.seeds})
    return pd.DataFrame(rows, columns=["terrain", "level", "mapper", "mean", "low", "high",
                                       "seeds"])
