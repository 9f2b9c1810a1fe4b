"""The time a mapper needs for a fidelity, read so that no time reading decides where.

A size needed for a fidelity is read off the (size, fidelity) Pareto front, interpolated
between its maps (:func:`alte.lab.studies.analysis.tradeoff.equal_fidelity`). A time read that way
would depend on which maps a run's readings put on the time front and which one first
(where reads start), both moved by noise. So the time a mapper needs for a fidelity
level is the least time among *its maps that reach the level*: a set fixed by the
fidelities alone. Each time is known within its spread
(:func:`alte.lab.studies.analysis.uncertainty.run_time_spreads`), so the least time within the
least of
the maps' lower and of their upper bounds. The levels are those the (basis functions,
fidelity) fronts are read at, unless a check fixes them.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from alte.lab.studies.analysis.tradeoff import equal_fidelity
from alte.lab.studies.analysis.uncertainty import run_time_spreads

__all__ = ["READ_COLUMNS", "time_at_fidelity"]

#: Columns of :func:`time_at_fidelity`.
READ_COLUMNS = ["terrain", "seed", "level", "mapper", "value", "low", "high"]


def _least(maps: pd.DataFrame, time: str, fidelity: str, levels: NDArray[np.float64],
           sign: float) -> NDArray[np.float64]:
    """(levels, 3): the least time, lower and upper bound of the maps reaching each level
    (signed fidelity at most the level); NaN where none does."""
    x = maps[time].to_numpy(dtype=np.float64)
    y = sign * maps[fidelity].to_numpy(dtype=np.float64)
    u = run_time_spreads(maps)
    ok = np.isfinite(x) & (x > 0) & np.isfinite(y)
    x, y, u = x[ok], y[ok], u[ok]
    reach = y[None, :] <= sign * levels[:, None]
    out = np.full((len(levels), 3), np.nan)
    for column, values in enumerate((x, x * np.exp(-u), x * np.exp(u))):
        least = np.where(reach, values[None, :], np.inf).min(axis=1, initial=np.inf)
        out[:, column] = np.where(reach.any(axis=1), least, np.nan)
    return out


def _levels(table: pd.DataFrame, mappers: Sequence[str], fidelity: str,
            higher_is_better: bool) -> dict[str, list[float]]:
    """Per terrain, the levels the (basis functions, fidelity) fronts are read at."""
    sizes = equal_fidelity(table, mappers, "basis_functions", fidelity=fidelity,
                           higher_is_better=higher_is_better)
    return {str(t): sorted(g["level"].unique()) for t, g in sizes.groupby("terrain")}


def time_at_fidelity(table: pd.DataFrame, mappers: Sequence[str], time: str, *,
                     fidelity: str = "mhd_m", levels: Sequence[float] = (),
                     higher_is_better: bool = False) -> pd.DataFrame:
    """The least ``time`` of each mapper's maps reaching each ``fidelity`` level, per
    terrain and seed, with its bounds (:data:`READ_COLUMNS`; module docstring). Terrains
    lacking a mapper are left out; ``levels`` fixes the levels."""
    sign = -1.0 if higher_is_better else 1.0
    fronts = None if len(levels) else _levels(table, mappers, fidelity, higher_is_better)
    rows = []
    for terrain, part in table[table["mapper"].isin(mappers)].groupby("terrain", sort=True):
        at = np.asarray(levels if fronts is None else fronts.get(str(terrain), []), float)
        if not at.size or set(part["mapper"]) != set(mappers):
            continue
        for (seed, mapper), maps in part.groupby(["seed", "mapper"], sort=True):
            reads = _least(maps, time, fidelity, at, sign)
            rows += [{"terrain": terrain, "seed": seed, "level": lv, "mapper": mapper,
                      "value": v, "low": lo, "high": hi}
                     for lv, (v, lo, hi) in zip(at.tolist(), reads, strict=True)]
    return pd.DataFrame(rows, columns=READ_COLUMNS)
