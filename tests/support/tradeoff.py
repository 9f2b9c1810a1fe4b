"""Synthetic trade-off tables with the schema of ``reports/tables/tradeoff.csv``.

Each mapper gets a parameter grid (>= 10 settings, the thesis' chosen settings
included); map size follows from the setting, MHD from the size through a power law
``scale * (size / 1000) ** -slope``, with a few percent of seeded noise per seed. The
other metrics follow from those two (time and machine-independent cost in proportion to
the size; obstacle recall and precision falling with MHD), so a test controls who wins by
choosing the scales and slopes (:class:`Curve`).
"""

from __future__ import annotations

import itertools
import json
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

__all__ = ["GRIDS", "Curve", "sweep_rows", "synthetic_tradeoff"]

_QT = [{"max_points": v} for v in (10, 25, 50, 100, 150, 200, 300, 500, 750, 1000)]
_A2 = [{"kappa": k, "max_res": r, "min_pts": p}
       for k, r, p in itertools.product((0.01, 0.05, 0.1, 1.0), (4, 5, 6), (10, 100))]
_OM = [{"resolution": v} for v in (0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0)]
_A3 = [{"min_pts": a, "min_pts_split": b, "max_res": r}
       for a, b, r in itertools.product((5, 20), (10, 40), (4, 5, 6))]
#: Parameter grids per mapper (each holds the thesis' chosen setting).
GRIDS: dict[str, list[dict[str, float]]] = {"quadtree": _QT, "alte2d": _A2, "octomap": _OM,
                                            "alte3d": _A3}


def _size(mapper: str, p: Mapping[str, float]) -> float:
    """Basis functions of a setting: from 100 to 100,000 over each grid."""
    if mapper == "quadtree":
        return 1e5 * 10 / p["max_points"]
    if mapper == "octomap":
        return 1e5 * (p["resolution"] / 8.0) ** 3
    if mapper == "alte2d":
        return 10 ** (p["max_res"] - 2 + 0.3 * np.log10(p["kappa"] * 100) / 2) * (
            1.05 if p["min_pts"] == 10 else 1.0)
    return 10 ** (p["max_res"] - 2 + 0.4 * (p["min_pts_split"] == 10)) * (
        1.02 if p["min_pts"] == 5 else 1.0)


@dataclass(frozen=True)
class Curve:
    """MHD = ``scale`` * (size / 1000) ** -``slope``; time = ``seconds`` per 1000 cells."""

    scale: float = 1.0
    slope: float = 0.3
    seconds: float = 0.01
    free_share: float = 0.0
    noise: float = 0.02


_DEFAULT = {"quadtree": Curve(), "alte2d": Curve(), "octomap": Curve(free_share=0.7),
            "alte3d": Curve()}
_CASE = {"quadtree": ("sim_lan_1", "sim_lan_2"), "alte2d": ("sim_lan_1", "sim_lan_2"),
         "octomap": ("sim_nav_1", "sim_nav_2"), "alte3d": ("sim_nav_1", "sim_nav_2")}


def _row(terrain: str, mapper: str, p: Mapping[str, float], seed: int, *, curve: Curve,
         rng: np.random.Generator) -> dict[str, object]:
    size = _size(mapper, p)
    mhd = curve.scale * (size / 1000.0) ** -curve.slope * (1 + curve.noise * rng.normal())
    occupied = size * (1 - curve.free_share)
    row: dict[str, object] = {
        "terrain": terrain, "mapper": mapper, "params": json.dumps(p, sort_keys=True),
        "seed": seed, "basis_functions": round(size), "occupied_cells": round(occupied),
        "memory_bytes": round(size * 64), "elapsed_s": curve.seconds * size / 1000.0,
        "elapsed_spread": 0.2, "map_cpu_s": curve.seconds * size / 1000.0,
        "map_cpu_spread": 0.05, "time_repeats": 3, "cost": round(size * 50),
        "cost_unit": "ray steps" if mapper == "octomap" else "cell updates",
        "mhd_m": mhd, "hd_m": 4.0 + 0.5 * rng.normal(), "mh_ab_m": mhd, "mh_ba_m": 0.5 * mhd,
        "accuracy_mean_m": 0.2 * mhd, "completeness": 1.0 - mhd / 5.0,
        "size_octaves": 5.0 if mapper.startswith("alte") else 2.0,
        "obstacle_recall": float(np.clip(1.0 - mhd / 4.0, 0.0, 1.0)),
        "obstacle_precision": float(np.clip(1.0 - mhd / 8.0, 0.0, 1.0)),
    }
    if mapper in ("quadtree", "alte2d"):
        row["height_rmse_m"] = 0.5 * mhd
    return row


def synthetic_tradeoff(curves: Mapping[str, Curve] | None = None, seeds: Sequence[int] = (0, 1, 2),
                       terrains: Mapping[str, Sequence[str]] | None = None,
                       rng_seed: int = 0) -> pd.DataFrame:
    """A trade-off table: every mapper of ``curves`` (default all four) on its case's
    terrains (``terrains`` overrides per mapper), every grid setting, every seed."""
    chosen = {**_DEFAULT, **(curves or {})}
    rng = np.random.default_rng(rng_seed)
    rows = [_row(terrain, mapper, p, seed, curve=curve, rng=rng)
            for mapper, curve in chosen.items()
            for terrain in (terrains or _CASE).get(mapper, _CASE[mapper])
            for seed in seeds for p in GRIDS[mapper]]
    return pd.DataFrame(rows)


def sweep_rows(mapper: str, xs: Sequence[float], columns: Mapping[str, Sequence[float]], *,
               param: str = "x", seeds: Sequence[int] = (0, 1, 2), terrain: str = "sim_lan_1",
               jitter: float = 0.0) -> pd.DataFrame:
    """One mapper's sweep over ``param`` with constant metrics but ``columns`` (per value
    of ``xs``; scaled by ``1 + jitter * seed``); size 100, 200, ... basis functions."""
    rows = []
    for seed in seeds:
        for i, x in enumerate(xs):
            row = {"terrain": terrain, "mapper": mapper, "params": json.dumps({param: x}),
                   "seed": seed, "basis_functions": 100 * (i + 1), "occupied_cells": 50,
                   "memory_bytes": 1000, "elapsed_s": 1.0, "mhd_m": 1.0, "hd_m": 5.0,
                   "accuracy_mean_m": 0.1, "completeness": 0.9}
            row.update({k: v[i] * (1 + jitter * seed) for k, v in columns.items()})
            rows.append(row)
    return pd.DataFrame(rows)
