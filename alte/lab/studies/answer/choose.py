"""Which map to build under a budget, read off the trade-off grid.

A *use* is one of the thesis' cases with its two mappers and the ground-truth metric that
ranks their maps (:data:`USES`; further mappers of the use's dimension in the grid, e.g. a
plugin, join its candidates: :mod:`~alte.lab.studies.answer.challengers`): landing (Quadtree
or 2D-ALTE, ranked by the true height RMSE, obstacle recall shown beside it) and urban
navigation (Octomap or 3D-ALTE, ranked by mean accuracy, the distance of the occupied
cells to the true surface, completeness shown beside it). A map covering less than half
of the true surface (:data:`MIN_COMPLETENESS`) is never chosen: few cells are accurate
cheaply, and a planner cannot use a map that misses most surfaces. Terrains are taken in
two groups of one scale (:data:`GROUPS`): the simulated urban-scale terrains and the lab
terrains.

A *candidate* is one mapper setting; on a group its size and time per scan are the
worst (largest) of its terrains' means over seeds, so a budget met holds on every terrain,
and its metrics are means over the group's terrains, one value per seed, with a 95 %
bootstrap interval over seeds. Under a :class:`Budget`:

* ``size``: the best truth among candidates of at most that many basis functions;
* ``time``: the best truth among candidates mapping a scan in at most that many ms
  (the mapper's CPU time over the grid's scans);
* ``need``: the smallest candidate whose truth meets the need on every terrain;
* ``cover`` (navigation): the best truth among candidates covering at least that share
  of the true surface on every terrain (completeness): ranked by mean accuracy alone, the
  pick may cover little more than :data:`MIN_COMPLETENESS`, so a planner that needs most
  surfaces states its need. Two needs are read off the candidates (the median and the
  best third of their worst-terrain completeness); others are the reader's (``cover``).

Time budgets and the need are read off the candidates (:func:`budgets`), so they sit
where the choice is a real one. A :class:`Choice` holds the pick, the other mapper's
best under the same budget, whether their difference in truth lies beyond its interval
(paired over seeds), and the pick the thesis' MHD would make instead.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np
import pandas as pd

from alte.lab.studies.analysis.tradeoff import METRICS, mapper_title
from alte.lab.studies.analysis.uncertainty import Interval, bootstrap_ci
from alte.lab.studies.obstacles import setting_text

__all__ = ["GROUPS", "MIN_COMPLETENESS", "SIZE_BUDGETS", "USES", "Budget", "Choice", "Pick",
           "Use", "budgets", "candidates", "choose", "ms_per_scan"]


@dataclass(frozen=True)
class Use:
    """A case of the thesis: its mappers (the thesis' two first), the truth that ranks them,
    a second one shown, and the dimension of its maps (``dims``)."""

    name: str
    case: str
    mappers: tuple[str, ...]
    truth: str
    second: str
    truth_higher: bool = False
    dims: int | None = None


#: The two uses the thesis studies.
USES = (Use("landing", "lan", ("quadtree", "alte2d"), "height_rmse_m", "obstacle_recall",
            dims=2),
        Use("navigation", "nav", ("octomap", "alte3d"), "accuracy_mean_m", "completeness",
            dims=3))
#: The least completeness of a map that may be chosen.
MIN_COMPLETENESS = 0.5
#: Terrain groups of one scale: name -> terrain-name prefix.
GROUPS = {"simulated": "sim_", "lab": "exp_"}
#: Size budgets (basis functions).
SIZE_BUDGETS = (1_000.0, 5_000.0, 20_000.0)


@dataclass(frozen=True)
class Budget:
    """A limit on size (basis functions), time (ms per scan), or a need on the truth."""

    kind: Literal["size", "time", "need", "cover"]
    limit: float

    def text(self, use: Use) -> str:
        """The budget in words, with its unit."""
        if self.kind == "size":
            return f"at most {self.limit:,.0f} basis functions"
        if self.kind == "time":
            return f"at most {self.limit:g} ms per scan"
        if self.kind == "cover":
            return f"completeness >= {self.limit:.2g} on every terrain"
        name, unit = METRICS.get(use.truth, (use.truth, ""))
        sign = ">=" if use.truth_higher else "<="
        return f"{name} {sign} {self.limit:.3g}{' ' + unit if unit else ''}"


@dataclass(frozen=True)
class Pick:
    """One candidate: mapper, setting, size, time per scan and metrics with intervals."""

    mapper: str
    setting: str
    size: float
    ms: float
    truth: Interval
    second: Interval
    mhd: Interval

    @property
    def name(self) -> str:
        """The mapper's display name."""
        return mapper_title(self.mapper)


@dataclass(frozen=True)
class Choice:
    """The pick under one budget on one terrain group (module docstring)."""

    use: Use
    group: str
    terrains: tuple[str, ...]
    budget: Budget
    best: Pick | None
    rival: Pick | None
    decided: bool
    by_mhd: Pick | None


def ms_per_scan(table: pd.DataFrame) -> pd.Series[float]:
    """Milliseconds of mapping per scan: the mapper's CPU time (wall time for tables
    without it) over the scans mapped (NaN where the table does not say how many)."""
    seconds = table["map_cpu_s"] if "map_cpu_s" in table else table["elapsed_s"]
    frames = table["frames"] if "frames" in table else pd.Series(np.nan, index=table.index)
    return 1000.0 * seconds.astype(float) / frames.astype(float)


def candidates(table: pd.DataFrame, use: Use, group: str) -> pd.DataFrame:
    """Per setting of the use's mappers on the group's terrains: size and ms per scan
    (worst terrain), every metric's per-seed group means (lists) and their means."""
    rows = table[table["mapper"].isin(use.mappers)
                 & table["terrain"].astype(str).str.startswith(GROUPS[group])]
    if rows.empty:
        return pd.DataFrame()
    rows = rows.assign(ms=ms_per_scan(rows))
    metrics = list(dict.fromkeys([use.truth, use.second, "mhd_m", "completeness"]))
    terrains = rows["terrain"].nunique()
    out = []
    for (mapper, params), mine in rows.groupby(["mapper", "params"], sort=True):
        if mine["terrain"].nunique() < terrains:
            continue
        means = mine.groupby("terrain")[["basis_functions", "ms"]].mean()
        seeds = mine.groupby("seed")[metrics].mean()
        item: dict[str, object] = {"mapper": mapper, "params": params,
                                   "size": float(means["basis_functions"].max()),
                                   "ms": float(means["ms"].max())}
        for metric in metrics:
            values = seeds[metric].to_numpy(float)
            item[metric] = values
            item[f"{metric}_mean"] = (float(np.mean(values[np.isfinite(values)]))
                                      if np.isfinite(values).any() else np.nan)
        by_terrain = mine.groupby("terrain")[[use.truth, "completeness"]].mean()
        item["worst"] = float(by_terrain[use.truth].agg("min" if use.truth_higher else "max"))
        item["worst_completeness"] = float(by_terrain["completeness"].min())
        item["covers"] = bool((by_terrain["completeness"] >= MIN_COMPLETENESS).all())
        out.append(item)
    pool = pd.DataFrame(out)
    return pool[pool["covers"]].reset_index(drop=True) if len(pool) else pool


def _round(value: float, digits: int) -> float:
    return float(f"{value:.{digits}g}")


def budgets(pool: pd.DataFrame, use: Use, cover: Sequence[float] = ()) -> list[Budget]:
    """The size budgets, two time budgets (the fastest quarter and three quarters of the
    candidates fit, one significant digit), a need met by the best third of the
    candidates on their worst terrain (two significant digits) and, where the use shows
    completeness beside its truth, completeness needs: ``cover`` and two read off the
    candidates (module docstring)."""
    out = [Budget("size", b) for b in SIZE_BUDGETS]
    if pool.empty:
        return out
    ms = pool["ms"].dropna()
    out += [Budget("time", _round(float(np.quantile(ms, q)), 1)) for q in (0.25, 0.75)
            if len(ms)]
    worst = pool["worst"].dropna()
    if len(worst):
        level = float(np.quantile(worst, 2 / 3 if use.truth_higher else 1 / 3))
        out.append(Budget("need", _round(level, 2)))
    if use.second == "completeness" and "worst_completeness" in pool:
        cover_of = pool["worst_completeness"].dropna()
        read = [_round(float(np.quantile(cover_of, q)), 2) for q in (0.5, 2 / 3)
                if len(cover_of)]
        out += [Budget("cover", c) for c in sorted({*read, *cover})]
    return list(dict.fromkeys(out))


def _pick(chosen: pd.DataFrame, use: Use) -> Pick:
    """The :class:`Pick` of a one-row frame of candidates."""
    row = chosen.iloc[0]
    return Pick(str(row["mapper"]), setting_text(row["params"]), float(row["size"]),
                float(row["ms"]), bootstrap_ci(row[use.truth]), bootstrap_ci(row[use.second]),
                bootstrap_ci(row["mhd_m"]))


def _best(pool: pd.DataFrame, column: str, higher: bool) -> pd.DataFrame | None:
    """The best candidate by ``column`` (the smaller of a tie) as a one-row frame."""
    ranked = pool.dropna(subset=[f"{column}_mean"])
    if ranked.empty:
        return None
    order = ranked.sort_values([f"{column}_mean", "size"], ascending=[not higher, True])
    return order.iloc[:1]


def _feasible(pool: pd.DataFrame, budget: Budget, use: Use) -> pd.DataFrame:
    if budget.kind == "size":
        return pool[pool["size"] <= budget.limit]
    if budget.kind == "time":
        return pool[pool["ms"] <= budget.limit]
    if budget.kind == "cover":
        return pool[pool["worst_completeness"] >= budget.limit]
    met = pool["worst"] >= budget.limit if use.truth_higher else pool["worst"] <= budget.limit
    return pool[met]


def _decided(best: pd.DataFrame, rival: pd.DataFrame, use: Use) -> bool:
    diff = (np.asarray(best[use.truth].iloc[0], float)
            - np.asarray(rival[use.truth].iloc[0], float))
    ci = bootstrap_ci(diff)
    return bool(ci.seeds > 1 and (ci.low > 0 or ci.high < 0))


def choose(pool: pd.DataFrame, use: Use, group: str, terrains: Sequence[str],
           budget: Budget) -> Choice:
    """The :class:`Choice` under ``budget`` among the candidates ``pool``."""
    fit = _feasible(pool, budget, use) if not pool.empty else pool
    if budget.kind == "need":
        ranked = fit.sort_values(["size", f"{use.truth}_mean"],
                                 ascending=[True, not use.truth_higher])
        best = ranked.iloc[:1] if len(ranked) else None
    else:
        best = _best(fit, use.truth, use.truth_higher) if len(fit) else None
    rival = by_mhd = None
    if best is not None:
        others = fit[fit["mapper"] != best["mapper"].iloc[0]]
        if budget.kind == "need":
            rival = others.sort_values("size").iloc[:1] if len(others) else None
        else:
            rival = _best(others, use.truth, use.truth_higher) if len(others) else None
            by_mhd = _best(fit, "mhd_m", False)
    decided = best is not None and rival is not None and _decided(best, rival, use)
    return Choice(use, group, tuple(terrains), budget,
                  _pick(best, use) if best is not None else None,
                  _pick(rival, use) if rival is not None else None, decided,
                  _pick(by_mhd, use) if by_mhd is not None else None)
