"""Experiments of thesis chapters 4-5: map one terrain with one mapper and measure it.

Data flows one way: terrain folder -> :class:`Dataset` (registered frames, cloud,
ground truth) -> :func:`run_mapper` (timed mapping, then metrics) -> :func:`sweep`
(a table of runs). Timing follows thesis 5.2.1: only the mapper calls are timed
(``time.perf_counter`` around ``insert``/``build``), never reading, down-sampling or
filtering. Octomap and both ALTE mappers are fed frame by frame as in the thesis;
Quadtree is built once on the final cloud (:data:`BATCH_MAPPERS`).
"""

from __future__ import annotations

import os
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd
from tqdm.auto import tqdm

from alte.errors import ParameterError
from alte.io import read_frames
from alte.mappers import make_mapper
from alte.mappers.base import Mapper
from alte.metrics import TrueSurface, ground_truth_metrics, hausdorff
from alte.registration import register, register_frames
from alte.sim import load_scenario
from alte.studies.thesis import SWEEPS, sweep_table

__all__ = ["BATCH_MAPPERS", "CUBE_DOMAIN_MAPPERS", "Dataset", "MapRun", "TruthOptions",
           "flat_metrics", "load_dataset", "map_metrics", "run_mapper", "surface_from_scene",
           "sweep"]

#: Mappers the thesis ran once on the final cloud instead of frame by frame.
BATCH_MAPPERS = frozenset({"quadtree"})

#: Mappers whose frame-by-frame insert needs a fixed domain (thesis 3.3: "an overall
#: domain is defined"); unless the caller passes ``domain``, they get the cube (2D-ALTE:
#: its square footprint) over the terrain's control volume, so ``max_res`` refines the
#: terrain rather than a power-of-two box grown around it.
CUBE_DOMAIN_MAPPERS = frozenset({"alte2d", "alte3d"})


@dataclass(frozen=True)
class TruthOptions:
    """Ground-truth metric settings (see :mod:`alte.metrics.truth`).

    ``tolerance`` (m): how close a map must come to a true surface to count it as
    mapped; ``n_samples``: surface samples drawn (3D); ``grid_step`` (m): x/y probe
    spacing of the 2D metrics; ``seed``: sampling seed.
    """

    tolerance: float = 0.2
    n_samples: int = 100_000
    grid_step: float = 0.2
    seed: int = 0


@dataclass(eq=False)
class Dataset:
    """One terrain ready for mapping.

    ``frames`` holds per kept frame its registered, down-sampled points and sensor
    origin; ``cloud`` is the merged registered cloud (set A of the Hausdorff metrics);
    ``surface``/``bounds`` the ground truth and control volume (None for real data).
    ``info`` carries the frame/point tallies of tables 5.5-5.6 and anything to plot.
    """

    name: str
    case: str
    frames: list[tuple[np.ndarray, np.ndarray]]
    cloud: np.ndarray
    origins: np.ndarray
    surface: TrueSurface | None = None
    bounds: np.ndarray | None = None
    info: dict[str, Any] = field(default_factory=dict)


@dataclass(eq=False)
class MapRun:
    """A finished map, its parameters and its metrics (a flat dict, JSON-ready)."""

    mapper_name: str
    params: dict[str, Any]
    mapper: Mapper
    metrics: dict[str, Any]


def surface_from_scene(scene: Any) -> TrueSurface:
    """A :class:`TrueSurface` from an :class:`alte.sim.scene.Scene` (names and classes kept)."""
    labels = {i: o.name for i, o in enumerate(scene.objects)}
    classes = {i: o.cls for i, o in enumerate(scene.objects)}
    return TrueSurface(scene.vertices, scene.triangles, scene.object_ids, labels, classes)


def _subsample(items: list[Any], limit: int | None) -> list[Any]:
    """At most ``limit`` items evenly spaced over the list (the whole flight, thinned)."""
    if limit is None or limit >= len(items):
        return items
    if limit < 1:
        raise ParameterError(f"frames={limit}: expected a positive integer or None")
    return [items[i] for i in np.unique(np.round(np.linspace(0, len(items) - 1, limit)))
            .astype(int)]


def load_dataset(folder: str | os.PathLike[str], frames: int | None = None,
                 voxel: float | None = None, progress: bool = False) -> Dataset:
    """Read a simulated terrain folder, register its frames and load its ground truth.

    ``frames`` keeps at most that many scans, evenly spaced over the flight (quick
    mode); ``voxel`` (m) overrides the scenario's recommended grid-average size.
    """
    scen = load_scenario(folder)
    frame_set = read_frames(scen.bag, progress=progress)
    chosen = _subsample(list(frame_set.frames), frames)
    size = scen.registration_voxel if voxel is None else float(voxel)
    kept = list(register_frames(chosen, frame_set.mount, voxel=size, crop_box=scen.crop_box,
                                progress=progress))
    per_frame = [(pts, origin) for _, pts, origin in kept]
    reg = register(chosen, frame_set.mount, voxel=size, crop_box=scen.crop_box)
    info = {
        "folder": str(folder), "voxel_m": size, "frames_in_bag": len(frame_set.frames),
        # frames used for registration (thesis tables 5.5/5.6) and those left with points
        "frames_used": len(chosen), "frames": len(per_frame), "points": len(reg.points),
        "counts": reg.counts,
        "time_s": np.array([f.time for f in chosen]) - chosen[0].time,
        "kept_time_s": np.array([f.time for f, _, _ in kept]) - chosen[0].time,
        "positions": np.array([f.position for f in chosen]),
        "quaternions": np.array([f.quaternion for f in chosen]),
        "title": scen.metadata.get("title", scen.name),
    }
    return Dataset(scen.name, scen.case, per_frame, reg.points, reg.origins,
                   surface_from_scene(scen.ground_truth),
                   np.asarray(scen.crop_box, dtype=np.float64).reshape(2, 3), info)


def _feed(mapper: Mapper, name: str, data: Dataset, progress: bool) -> float:
    """Map ``data`` and return the seconds spent inside the mapper calls only."""
    if name in BATCH_MAPPERS:
        start = time.perf_counter()
        mapper.build(data.cloud, data.origins)
        return time.perf_counter() - start
    elapsed = 0.0
    for points, origin in tqdm(data.frames, desc=name, unit="frame", disable=not progress,
                               leave=False):
        start = time.perf_counter()
        mapper.insert(points, origin)
        elapsed += time.perf_counter() - start
    return elapsed


def _size_spread(mapper: Mapper) -> dict[str, float]:
    """Cell edge range of the map's known cells: the "adaptability" of tables 5.1-5.2."""
    cells = mapper.cells()
    known = np.isfinite(cells.centers).all(axis=1)
    edge = cells.sizes[known, 0]
    if edge.size == 0:
        return {"cell_min_m": np.nan, "cell_max_m": np.nan, "size_octaves": np.nan}
    lo, hi = float(edge.min()), float(edge.max())
    return {"cell_min_m": lo, "cell_max_m": hi, "size_octaves": float(np.log2(hi / lo))}


def map_metrics(mapper: Mapper, data: Dataset, truth: TruthOptions | None) -> dict[str, Any]:
    """Thesis metrics (basis functions, HD, MHD) plus, with ``truth``, ground-truth ones.

    A map with no occupied cell (e.g. 3D-ALTE at a coarse max_res) gets NaN HD/MHD.
    """
    corners = mapper.corners()
    out: dict[str, Any] = {
        "basis_functions": int(mapper.basis_functions), "memory_bytes": int(mapper.memory_bytes),
        "occupied_cells": int(mapper.cells().occupied.sum()), **_size_spread(mapper),
    }
    if len(corners) == 0:  # nothing occupied: HD/MHD are undefined, not zero
        out.update(dict.fromkeys(("hd_m", "mhd_m", "hd_minus_mhd_m", "h_ab_m", "h_ba_m",
                                  "mh_ab_m", "mh_ba_m"), float("nan")))
    else:
        hd = hausdorff(data.cloud, corners)
        out.update({"hd_m": hd.hd, "mhd_m": hd.mhd, "hd_minus_mhd_m": hd.hd - hd.mhd,
                    "h_ab_m": hd.h_ab, "h_ba_m": hd.h_ba, "mh_ab_m": hd.mh_ab,
                    "mh_ba_m": hd.mh_ba})
    if truth is not None and data.surface is not None:
        out.update(ground_truth_metrics(
            mapper.cells(), data.surface, dims=mapper.dims, cloud=data.cloud, bounds=data.bounds,
            tolerance=truth.tolerance, n_samples=truth.n_samples, grid_step=truth.grid_step,
            seed=truth.seed))
    return out


def flat_metrics(metrics: Mapping[str, Any]) -> dict[str, Any]:
    """Scalar metrics for a table row: per-class completeness becomes ``completeness_<class>``,
    per-object values (too many columns) stay in the JSON only."""
    out = {k: v for k, v in metrics.items() if not isinstance(v, Mapping)}
    for cls, value in metrics.get("completeness_by_class", {}).items():
        out[f"completeness_{cls}"] = value
    return out


def _auto_domain(name: str, params: Mapping[str, Any], data: Dataset) -> dict[str, str]:
    """``domain`` = the cube (xmin, ymin, zmin, edge) over the control volume, when needed."""
    if name not in CUBE_DOMAIN_MAPPERS or "domain" in params or data.bounds is None:
        return {}
    lo, hi = (np.asarray(b, dtype=np.float64) for b in data.bounds)
    edge = float(np.max(hi - lo)) * (1 + 1e-9) + 1e-9  # lo + edge must not round below hi
    return {"domain": ",".join(repr(float(v)) for v in (*lo, edge))}


def run_mapper(data: Dataset, name: str, params: Mapping[str, Any] | None = None, *,
               truth: TruthOptions | None = None, progress: bool = False) -> MapRun:
    """Map ``data`` with mapper ``name`` and ``params``; time it and measure the map.

    Mappers in :data:`CUBE_DOMAIN_MAPPERS` get the control volume's cube as ``domain``
    unless ``params`` has one (the run records ``params`` as given).
    """
    params = dict(params or {})
    mapper = make_mapper(name, **params, **_auto_domain(name, params, data))
    elapsed = _feed(mapper, name, data, progress)
    metrics = {"elapsed_s": elapsed, **map_metrics(mapper, data, truth)}
    return MapRun(name, params, mapper, metrics)


def sweep(data: Dataset, table: int, rows: Sequence[int] | None = None, *,
          extra: Mapping[str, Any] | None = None, truth: TruthOptions | None = None,
          progress: bool = True) -> tuple[pd.DataFrame, list[MapRun]]:
    """Run the parameter rows of table 5.``table`` (7, 8, 9 or 12) on ``data``.

    ``rows`` picks thesis rows by index (default: all six); ``extra`` adds fixed mapper
    parameters to every row (e.g. a ground plane). Returns the table (our metrics beside
    the ``thesis_*`` columns; flat metrics only) and the runs, for figures.
    """
    if table not in SWEEPS:
        raise ParameterError(f"table 5.{table} is not a sweep; sweeps: {sorted(SWEEPS)}")
    spec = SWEEPS[table]
    chosen = list(range(len(spec["rows"]))) if rows is None else list(rows)
    bad = [r for r in chosen if not 0 <= r < len(spec["rows"])]
    if bad or not chosen:
        raise ParameterError(f"table 5.{table}: rows {bad or chosen} not in 0..5")
    thesis = sweep_table(table).iloc[chosen].reset_index(drop=True)
    runs = [run_mapper(data, spec["mapper"], {**spec["rows"][r][0], **(extra or {})},
                       truth=truth, progress=False)
            for r in tqdm(chosen, desc=f"table 5.{table}", unit="map", disable=not progress)]
    ours = pd.DataFrame([flat_metrics(run.metrics) for run in runs])
    ours.insert(0, "thesis_row", chosen)
    return pd.concat([thesis, ours], axis=1), runs
