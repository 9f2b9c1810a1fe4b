"""The trade-off fronts on a real sequence: do the simulated orders hold on real data?

The sequence (``balm_seq``: 77 real scans with the reference trajectory of a bundle
adjustment, its ``/lidar_pose`` topic) goes through the one pipeline twice, both times
with the recorded poses: every scan registered is the *reference cloud*, the real
stand-in for the simulator's true surface; ``frames`` scans of it, evenly spaced, are
what the maps are made from, as the simulated grid maps 20 scans per mission. Every
mapper's settings (:data:`FRONT_GRID`, over the cube of the data) give one row in the
schema of the trade-off table (``terrain`` = the sequence, ``seed`` 0), so its fronts
and equal-size reads are those of :mod:`alte.lab.studies.analysis.tradeoff`:

* the thesis' MHD (and HD) against the cloud the map was made from;
* the distance to the reference cloud (:func:`reference_metrics`), defined as the
  ground-truth metrics of :mod:`alte.metrics.truth` with the reference points in place
  of the true mesh: ``accuracy_mean_m`` (cell centre, or a 2D cell's (x, y, height), to
  the nearest reference point), ``completeness`` (3D: share of reference points within
  ``tolerance`` of an occupied box; 2D: share of raster pixels whose highest reference
  point the map's height meets within ``tolerance``) and, for 2D maps,
  ``height_rmse_m`` against that highest point per pixel.
"""

from __future__ import annotations

import json
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
from numpy.typing import NDArray
from scipy.spatial import cKDTree

from alte.lab.studies.experiments import measure
from alte.lab.studies.landing import RasterGeometry
from alte.lab.studies.obstacles import map_raster
from alte.lab.studies.realdata.data import RealData
from alte.lab.studies.thesis.numbers import CASE_MAPPERS
from alte.mappers.base import Cells
from alte.metrics.truth import distance_to_boxes
from alte.pipeline import (
    DomainPolicy,
    FrameSettings,
    MapSettings,
    PoseSource,
    Registered,
    open_input,
)
from alte.pipeline import prepare as register
from alte.progress import bar as progress_bar

__all__ = ["FRONT_COLUMNS", "FRONT_GRID", "SEQUENCE", "RealSequence", "front_table",
           "reference_metrics", "sequence_data"]

#: The real sequence with reference poses (``<realdata>/balm_seq/bag``).
SEQUENCE = "balm_seq"
#: Settings per mapper for the real fronts: each spans its mapper's range of sizes on a
#: 190 m scene (the cube over the data), from about 100 to 100,000 basis functions.
FRONT_GRID: dict[str, list[dict[str, float]]] = {
    "quadtree": [{"max_points": v} for v in (10, 25, 50, 100, 200, 500, 1000)],
    "alte2d": [{"kappa": k, "max_res": r, "min_pts": 10} for k in (0.01, 0.1)
               for r in (5, 6, 7, 8)],
    "octomap": [{"resolution": v} for v in (0.25, 0.5, 1.0, 1.5, 2.0)],
    "alte3d": [{"max_res": r, "min_pts": p, "min_pts_split": 10} for r in (5, 6, 7, 8)
               for p in (5, 20)],
}
#: Columns of :func:`front_table` (the trade-off schema's, plus the reference size).
FRONT_COLUMNS = ("terrain", "case", "mapper", "params", "seed", "basis_functions",
                 "occupied_cells", "memory_bytes", "elapsed_s", "mhd_m", "hd_m",
                 "accuracy_mean_m", "completeness", "height_rmse_m", "frames", "points",
                 "reference_points")
_CASE = {m: case for case, pair in CASE_MAPPERS.items() for m in pair}


@dataclass(frozen=True, eq=False)
class RealSequence:
    """A real sequence registered twice: the maps' input and the reference cloud."""

    name: str
    data: Registered
    reference: NDArray[np.float64]


def sequence_data(data: RealData, *, frames: int = 20, voxel: float = 0.2,
                  cache: str | os.PathLike[str] | None = None,
                  name: str = SEQUENCE) -> RealSequence | None:
    """``name``'s bag with its recorded poses: ``frames`` scans to map and every scan as
    the reference cloud (each grid-averaged to ``voxel`` m; cached in ``cache``); None
    when the real-data folder is absent."""
    if not data.available:
        return None
    source = open_input(data.file(name, "bag"))
    where = Path(cache) if cache is not None else None
    every = register(source, FrameSettings(voxel=voxel, poses=PoseSource.RECORDED), cache=where)
    some = register(source, FrameSettings(frames=frames, voxel=voxel, poses=PoseSource.RECORDED),
                    cache=where)
    return RealSequence(name, some, np.asarray(every.cloud, dtype=np.float64))


def _top_raster(points: NDArray[np.float64], grid: RasterGeometry) -> NDArray[np.float64]:
    """Highest point per pixel (NaN where none)."""
    ny, nx = grid.shape
    rc = grid.index(points[:, :2])
    inside = (rc[:, 0] >= 0) & (rc[:, 0] < ny) & (rc[:, 1] >= 0) & (rc[:, 1] < nx)
    top = np.full(ny * nx, -np.inf)
    np.maximum.at(top, rc[inside, 0] * nx + rc[inside, 1], points[inside, 2])
    return np.where(np.isfinite(top), top, np.nan).reshape(grid.shape)


def reference_metrics(cells: Cells, dims: int, reference: NDArray[np.float64], *,
                      tolerance: float = 0.2, step: float = 0.5,
                      samples: int = 50_000, seed: int = 0) -> dict[str, float]:
    """The map's distance to the reference cloud (module docstring); ``samples``
    reference points (seeded) are tested for 3D completeness."""
    finite = np.isfinite(cells.centers).all(axis=1)
    keep = finite if dims == 2 else finite & cells.occupied.astype(bool)
    out = {"accuracy_mean_m": float("nan"), "completeness": float("nan"),
           "height_rmse_m": float("nan")}
    if keep.any():
        dist, _ = cKDTree(reference).query(cells.centers[keep], k=1, workers=-1)
        out["accuracy_mean_m"] = float(np.mean(dist))
    if dims == 3:
        rng = np.random.default_rng(seed)
        pick = reference if len(reference) <= samples else reference[
            rng.choice(len(reference), samples, replace=False)]
        near = distance_to_boxes(pick, cells.centers[keep], cells.sizes[keep], tolerance)
        out["completeness"] = float(np.isfinite(near).mean())
        return out
    grid = RasterGeometry.from_bounds(np.array([reference.min(0), reference.max(0)]), step)
    truth = _top_raster(reference, grid)
    shown = map_raster(cells, 2, grid, 0.0).height
    both = np.isfinite(truth) & np.isfinite(shown)
    err = shown[both] - truth[both]
    out["height_rmse_m"] = float(np.sqrt(np.mean(err**2))) if err.size else float("nan")
    seen = np.isfinite(truth)
    out["completeness"] = float(np.mean(np.abs(np.nan_to_num(shown[seen], nan=np.inf)
                                               - truth[seen]) <= tolerance))
    return out


def front_table(sequence: RealSequence | None,
                grid: Mapping[str, Sequence[Mapping[str, object]]] | None = None, *,
                tolerance: float = 0.2, progress: bool = True) -> pd.DataFrame:
    """One row per mapper and setting of ``grid`` (default :data:`FRONT_GRID`) on the
    sequence (:data:`FRONT_COLUMNS`); empty when ``sequence`` is None."""
    if sequence is None:
        return pd.DataFrame(columns=list(FRONT_COLUMNS))
    runs = [(m, dict(p)) for m, rows in (grid or FRONT_GRID).items() for p in rows]
    rows = []
    for mapper, params in progress_bar(runs, desc=sequence.name, unit="map", disable=not progress):
        spec = MapSettings(mapper, params, domain=DomainPolicy.DATA)
        found = measure(sequence.data, mapper, spec=spec)
        cells = found.mapper.cells()
        m = found.metrics
        rows.append({
            "terrain": sequence.name, "case": _CASE.get(mapper, ""), "mapper": mapper,
            "params": json.dumps(params, sort_keys=True), "seed": 0,
            "basis_functions": m.basis_functions, "occupied_cells": m.occupied_cells,
            "memory_bytes": m.memory_bytes, "elapsed_s": m.elapsed_s, "mhd_m": m.mhd_m,
            "hd_m": m.hd_m, **reference_metrics(cells, found.mapper.dims, sequence.reference,
                                                tolerance=tolerance),
            "frames": len(sequence.data), "points": len(sequence.data.cloud),
            "reference_points": len(sequence.reference)})
    return pd.DataFrame(rows, columns=list(FRONT_COLUMNS))
