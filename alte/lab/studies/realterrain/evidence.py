"""Real-terrain evidence for the answer, two ways, in the trade-off table's schema.

For each :class:`~alte.lab.studies.realterrain.sites.Site` the tiles are imported once
(:func:`alte.sim.real.import_terrain`), then:

* **(a) flown** (``evidence = flown``): the thesis' landing mission is flown over the
  imported surface and mapped by Quadtree and 2D-ALTE, the navigation mission by Octomap
  and 3D-ALTE, ``frames`` scans each (evenly spaced, as the trade-off grid maps 20 per
  mission), simulation seeds ``seeds``; every map is measured against the exact truth
  (the imported mesh: height RMSE, mean accuracy, completeness) as on the built-in
  terrains, with the landing maps' obstacle identification against its objects;
* **(b) points** (``evidence = points``): the tile's own points are mapped, with a seeded
  random 20 % of them (every class) held back: the maps are made of the other 80 %
  (seen from 100 m above the tile's highest point over its centre, an airborne sensor:
  Octomap's rays then unlimited in range, its finest voxel 0.5 m) and scored against the
  held-back points as the real sequence's fronts are (:func:`~alte.lab.studies.realdata.
  reference_metrics`: distance of the cells to the nearest held-back point, 3D
  completeness, 2D height RMSE against the highest held-back point per 1 m pixel), and
  the 2D maps' ``ground_rmse_m`` at the held-back ground points whose cell of the
  imported surface is bare earth (where a vehicle lands), as ground-filter benchmarks
  score against reference ground. Each seed holds back another 20 %.

With ``plugins``, every installed plugin mapper of a case's dimension (2D: landing, 3D:
navigation) is mapped beside the thesis' two, with the rows the grid gives it or else
its own ``settings_grid``; ``mappers`` restricts a run to the mappers named (e.g. a
plugin's rows added to committed evidence).

Every row carries ``terrain`` (the site), ``terrain_class``, ``evidence``, ``case``,
the mapper and setting, ``seed``, size, time, MHD/HD and the truth columns.
"""

from __future__ import annotations

import itertools
import json
import os
import tempfile
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from alte.errors import AlteError
from alte.io.points.pointfiles import write_points
from alte.lab.studies.experiments import Measured, measure
from alte.lab.studies.obstacles import obstacle_columns, obstacle_options, obstacle_scores
from alte.lab.studies.realdata.fronts import reference_metrics
from alte.lab.studies.realdata.ground import map_heights
from alte.lab.studies.realterrain.sites import SITES, Site, surface_figures, terrain_class
from alte.lab.studies.thesis.numbers import CASE_MAPPERS
from alte.mappers.base import Cells
from alte.metrics.options import TruthSettings
from alte.pipeline import DomainPolicy, FrameSettings, MapSettings, open_input, prepare
from alte.progress import bar as progress_bar
from alte.sim.real import Flight, Imported, import_terrain, terrain_tiles, write_imported

__all__ = ["COLUMNS", "GRID", "HOLD_BACK", "Mappers", "evidence_rows", "site_rows"]

#: Settings per mapper: each spans its mapper's sizes on a 120 m site.
GRID: dict[str, list[dict[str, float]]] = {
    "quadtree": [{"max_points": v} for v in (25, 50, 100, 200, 350, 1000)],
    "alte2d": [{"kappa": k, "max_res": r, "min_pts": 10} for k in (0.01, 0.1)
               for r in (4, 5, 6, 7)],
    "octomap": [{"resolution": v} for v in (0.5, 1.0, 2.0, 4.0)],
    "alte3d": [{"max_res": r, "min_pts": p, "min_pts_split": 10} for r in (5, 6, 7)
               for p in (5, 20)],
}
#: Share of the tile's points held back as the reference of evidence (b).
HOLD_BACK = 0.2
#: The table's first columns.
COLUMNS = ("terrain", "terrain_class", "evidence", "case", "mapper", "params", "seed",
           "basis_functions", "occupied_cells", "memory_bytes", "elapsed_s", "map_cpu_s",
           "mhd_m", "hd_m", "accuracy_mean_m", "completeness", "height_rmse_m",
           "ground_rmse_m", "obstacle_recall", "obstacle_precision", "frames", "points",
           "reference_points", "slope_deg", "building_share", "cover_share")
_TRUTH = TruthSettings(tolerance=0.2, n_samples=20_000, grid_step=0.25)
_MISSION = {"lan": "landing", "nav": "navigation"}
_Grid = Mapping[str, Sequence[Mapping[str, float]]]


def _import(site: Site, root: Path, mission: str) -> Imported:
    return import_terrain([root / t for t in site.tiles], Flight(mission=mission),  # type: ignore[arg-type]
                          name=f"{site.name}_{_MISSION_CASE[mission]}", crs=site.crs,
                          ground=root / site.ground if site.ground else None,
                          region=site.region)


_MISSION_CASE = {"landing": "lan", "navigation": "nav"}


def _row(measured: Measured, case: str, seed: int, extra: Mapping[str, object]
         ) -> dict[str, object]:
    m = measured.metrics
    return {"case": case, "mapper": measured.name,
            "params": json.dumps(measured.params.as_dict(), sort_keys=True), "seed": seed,
            "basis_functions": m.basis_functions, "occupied_cells": m.occupied_cells,
            "memory_bytes": m.memory_bytes, "elapsed_s": m.elapsed_s,
            "map_cpu_s": m.map_cpu_s, "mhd_m": m.mhd_m, "hd_m": m.hd_m, **extra}


@dataclass(frozen=True)
class Mappers:
    """Which mappers a run maps: the thesis' pair of each case, with ``plugins`` the
    installed plugins of the case's dimension, restricted to ``only`` when given."""

    plugins: bool = False
    only: tuple[str, ...] = ()

    def of(self, case: str, grid: _Grid) -> list[tuple[str, dict[str, object]]]:
        """(mapper name, setting) of ``case``: the grid's rows, a plugin's own settings
        grid where the grid has none."""
        from alte.mappers import registry

        names = list(CASE_MAPPERS[case])
        own: dict[str, list[dict[str, object]]] = {}
        if self.plugins:
            for cls in registry.plugins(dims=2 if case == "lan" else 3):
                names.append(cls.name)
                keys = list(cls.settings_grid)
                own[cls.name] = [dict(zip(keys, v, strict=True))
                                 for v in itertools.product(*cls.settings_grid.values())]
        return [(m, dict(p)) for m in names if not self.only or m in self.only
                for p in (grid[m] if m in grid else own.get(m, []))]


def _grid(case: str, grid: _Grid, mappers: Mappers) -> list[tuple[str, dict[str, object]]]:
    return mappers.of(case, grid)


def _flown(site: Site, root: Path, case: str, seed: int,
           how: tuple[Path, int, _Grid, Mappers]) -> list[dict[str, object]]:
    data_dir, frames, grid, mappers = how
    imported = _import(site, root, _MISSION[case])
    folder = write_imported(imported, data_dir, seed=seed, frames=frames, force=True)
    data = prepare(open_input(folder))
    rows = []
    for mapper, params in _grid(case, grid, mappers):
        found = measure(data, mapper, params, truth=_TRUTH)
        t = found.metrics.truth
        extra: dict[str, object] = {
            "accuracy_mean_m": t.accuracy_mean_m if t else np.nan,
            "completeness": t.completeness if t else np.nan,
            "height_rmse_m": t.height_rmse_m if t else np.nan,
            "within_2sigma": t.within_2sigma if t else np.nan,
            "sigma_mean_m": t.sigma_mean_m if t else np.nan,
            "frames": len(data), "points": len(data.cloud)}
        if case == "lan":
            extra |= _obstacles(data, found, site.name)
        rows.append(_row(found, case, seed, extra))
    return rows


def _obstacles(data: object, found: Measured, name: str) -> dict[str, object]:
    try:
        scores = obstacle_scores(data, found.mapper.cells(), found.mapper.dims,  # type: ignore[arg-type]
                                 obstacle_options(name))
    except AlteError:  # e.g. no pixel of the crop sees the ground
        return {}
    cols = obstacle_columns(scores)
    return {k: cols.get(k, np.nan) for k in ("obstacle_recall", "obstacle_precision")}


def _ground_rmse(cells: Cells, held: NDArray[np.float64], on_ground: NDArray[np.bool_]
                 ) -> float:
    if not on_ground.any():
        return float("nan")
    err = map_heights(cells, held[on_ground]) - held[on_ground, 2]
    err = err[np.isfinite(err)]
    return float(np.sqrt(np.mean(err**2))) if err.size else float("nan")


def _bare_cells(imported: Imported, points: NDArray[np.float64]) -> NDArray[np.bool_]:
    """Whether each point (local metres) lies in a bare-earth cell of the surfaces."""
    s, o = imported.surfaces, imported.origin
    ny, nx = s.shape
    col = np.clip(((points[:, 0] + o[0] - s.x0) / s.step).astype(int), 0, nx - 1)
    row = np.clip(((points[:, 1] + o[1] - s.y0) / s.step).astype(int), 0, ny - 1)
    bare: NDArray[np.bool_] = s.label[row, col] == 0
    return bare


def _points(site: Site, root: Path, case: str, seed: int, *, grid: _Grid,
            mappers: Mappers) -> list[dict[str, object]]:
    imported = _import(site, root, _MISSION[case])
    pts, ground = _tile_points(imported, site, root)
    held = np.random.default_rng(seed).random(len(pts)) < HOLD_BACK
    reference, kept = pts[held], pts[~held]
    on_ground = ground[held] & _bare_cells(imported, reference)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        path = write_points(Path(tmp) / "kept.npz", kept)
        above = (*np.mean(kept[:, :2], axis=0).tolist(), float(kept[:, 2].max()) + 100.0)
        data = prepare(open_input(path), FrameSettings(origin=above))
        for mapper, setting in _grid(case, grid, mappers):
            # An airborne sensor: Octomap's rays longer than a VLP-16's.
            if mapper == "octomap" and float(str(setting["resolution"])) > 2.0:
                continue  # 0.25 m voxels along 100 m rays: millions of free leaves
            params = {**setting, "max_range": -1.0} if mapper == "octomap" else setting
            found = measure(data, mapper, spec=MapSettings(mapper, params,
                                                       domain=DomainPolicy.DATA))
            cells = found.mapper.cells()
            scores = reference_metrics(cells, found.mapper.dims, reference, step=1.0)
            extra: dict[str, object] = {
                **scores, "ground_rmse_m": _ground_rmse(cells, reference, on_ground)
                if found.mapper.dims == 2 else np.nan,
                "frames": 1, "points": len(kept), "reference_points": len(reference)}
            rows.append(_row(found, case, seed, extra))
    return rows


def _tile_points(imported: Imported, site: Site, root: Path
                 ) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """The site's points in local metres with their ground flags (read again, cropped)."""
    tiles, _ = terrain_tiles([root / t for t in site.tiles], crs=site.crs,
                             ground=root / site.ground if site.ground else None,
                             region=site.region)
    pts = np.vstack([t.points for t in tiles]) - imported.origin
    return pts, np.concatenate([t.ground for t in tiles])


def site_rows(site: Site, root: str | os.PathLike[str], data_dir: str | os.PathLike[str], *,
              seeds: Sequence[int] = (0, 1, 2), frames: int = 20,
              grid: Mapping[str, Sequence[Mapping[str, float]]] | None = None,
              evidence: Sequence[str] = ("flown", "points"),
              mappers: Mappers | None = None) -> pd.DataFrame:
    """Both kinds of evidence on one site (module docstring), every seed and use (a case
    none of whose mappers runs is skipped)."""
    grid = grid or GRID
    mappers = mappers or Mappers()
    where, data = Path(root), Path(data_dir)
    imported = _import(site, where, "landing")
    figures = surface_figures(imported.surfaces)
    label = terrain_class(imported.surfaces, site.stated)
    rows: list[dict[str, object]] = []
    for case in [c for c in ("lan", "nav") if _grid(c, grid, mappers)]:
        for seed in seeds:
            if "flown" in evidence:
                rows += [{"evidence": "flown", **r}
                         for r in _flown(site, where, case, seed,
                                         (data, frames, grid, mappers))]
            if "points" in evidence:
                rows += [{"evidence": "points", **r}
                         for r in _points(site, where, case, seed, grid=grid,
                                          mappers=mappers)]
    table = pd.DataFrame(rows).assign(terrain=site.name, terrain_class=label, **figures)
    return table.reindex(columns=[*COLUMNS, *[c for c in table if c not in COLUMNS]])


def evidence_rows(root: str | os.PathLike[str], data_dir: str | os.PathLike[str], *,
                  sites: Sequence[Site] = SITES, progress: bool = True,
                  **options: object) -> pd.DataFrame:
    """:func:`site_rows` of every site whose tiles are present under ``root``."""
    present = [s for s in sites if all((Path(root) / t).is_file() for t in s.tiles)]
    parts = [site_rows(s, root, data_dir, **options)  # type: ignore[arg-type]
             for s in progress_bar(present, desc="real terrains", unit="site",
                                   disable=not progress)]
    return pd.concat(parts, ignore_index=True) if parts else pd.DataFrame(columns=list(COLUMNS))
