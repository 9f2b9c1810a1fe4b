"""Landing-zone experiments: map a terrain, detect sites, score them against the truth.

Data flow: a registered terrain (:func:`alte.lab.studies.experiments.terrain`) ->
:func:`alte.pipeline.run` (the 2D map, any 2D mapper) -> :func:`rasterise` over the
control volume (with a height sigma bound, pixels the map is less sure of are unknown)
-> :func:`detect_sites` -> scores against :func:`truth_centres` of the same raster.
:func:`landing_table` gives one row per terrain x mapper x parameter set: the chapter 4
parameters of the terrain and two rows of each chapter 5 sweep (:data:`SWEEP_ROWS`), the
rows of further mappers' settings grids (plugins: :func:`alte.mappers.registry.plugins`)
and, for a map with a height variance, its setting again with the sigma bound
:data:`~alte.lab.studies.landing.params.SIGMA_OF_OBSTACLE`; written by
:func:`write_landing_table` as ``table_landing.csv``.
"""

from __future__ import annotations

import itertools
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from alte.errors import MetricsError, ParameterError
from alte.lab.studies.analysis.tables import write_csv
from alte.lab.studies.experiments import ground_truth, terrain
from alte.lab.studies.landing.detect import Centres, Detection, detect_sites
from alte.lab.studies.landing.params import SIGMA_OF_OBSTACLE, LandingSettings, landing_params
from alte.lab.studies.landing.raster import RasterGeometry, rasterise, rasterise_sigma
from alte.lab.studies.landing.truth import score_detection, truth_centres
from alte.lab.studies.thesis.numbers import SWEEPS, mapper_params
from alte.mappers import VARIANCE, Mapper, registry
from alte.pipeline import MapRun, MapSettings, Registered, run
from alte.progress import bar as progress_bar
from alte.types import JSONDict

__all__ = ["GRID_ROWS", "SWEEP_ROWS", "LandingRun", "evaluate_landing", "landing_grid",
           "landing_param_sets", "landing_summary", "landing_table", "landing_truth",
           "load_terrains", "score_landing", "write_landing_table"]

#: Rows of a further mapper's settings grid the table runs (evenly spaced when it has more).
GRID_ROWS = 7
#: A parameter set: (label, mapper: a thesis mapper's name or a class, parameters).
ParamSet = tuple[str, "str | type[Mapper]", dict[str, object]]
#: Rows of the chapter 5 sweeps run besides the chapter 4 parameters: table 5.7
#: (Quadtree max_points 100 and 500) and table 5.9 (2D-ALTE rows 1 and 4).
SWEEP_ROWS: dict[str, tuple[int, tuple[int, ...]]] = {"quadtree": (7, (1, 4)),
                                                      "alte2d": (9, (0, 4))}


@dataclass(eq=False)
class LandingRun:
    """One map with its detected sites, the truth it was scored on and the scores."""

    terrain: str
    label: str
    landing: LandingSettings
    map_run: MapRun
    detection: Detection
    truth: Centres | None
    scores: dict[str, float]


def landing_grid(data: Registered, params: LandingSettings) -> RasterGeometry:
    """The raster over the input's control volume (its points' extent when it has none)."""
    box = data.spec.crop if data.spec.crop is not None else data.bounds()
    return RasterGeometry.from_bounds(box.array(), params.step)


def landing_truth(data: Registered, params: LandingSettings) -> Centres:
    """Truly safe centres of a simulated terrain on :func:`landing_grid`."""
    truth = ground_truth(data)
    if truth is None:
        raise MetricsError(f"landing truth: {data.source.path} has no ground truth "
                           "(real recordings cannot be scored)")
    return truth_centres(truth.surface, landing_grid(data, params), params,
                         z_start=float(truth.bounds.hi[2]))


def _landing_spec(mapper: str | type[Mapper], params: Mapping[str, object] | None,
                  landing: LandingSettings) -> MapSettings:
    """The map to make, refused when it cannot carry the landing test."""
    spec = MapSettings(mapper, dict(params or {}))
    if spec.cls.dims != 2:
        usable = ", ".join(c.name for c in registry.classes() if c.dims == 2)
        raise ParameterError(f"landing: mapper {spec.cls.name!r} is not a 2D mapper; use one "
                             f"of {usable}")
    if landing.max_height_sigma is not None and VARIANCE not in spec.cls.layers:
        raise ParameterError(f"landing: max_height_sigma={landing.max_height_sigma} needs a "
                             f"map whose cells carry a height variance; {spec.cls.name!r} "
                             "has none")
    return spec


def _detect(data: Registered, result: MapRun, landing: LandingSettings, truth: Centres | None,
            label: str) -> LandingRun:
    """Sites on the map of ``result`` (pixels over the sigma bound unknown), scored."""
    grid = landing_grid(data, landing)
    cells = result.mapper.cells()
    height = rasterise(cells, grid)
    if landing.max_height_sigma is not None:
        height[~(rasterise_sigma(cells, grid) <= landing.max_height_sigma)] = np.nan
    detection = detect_sites(height, grid, landing)
    if truth is None and ground_truth(data) is not None:
        truth = landing_truth(data, landing)
    if truth is not None:
        scores = score_detection(detection, truth, landing)
    else:
        scores = {"sites": len(detection.sites), "chosen": len(detection.chosen)}
    return LandingRun(data.source.name, label, landing, result, detection, truth, scores)


def evaluate_landing(data: Registered, mapper: str | type[Mapper],
                     params: Mapping[str, object] | None, landing: LandingSettings, *,
                     truth: Centres | None = None, label: str = "") -> LandingRun:
    """Map ``data`` with ``mapper``/``params``, detect sites and score them when truth exists.

    ``truth`` (from :func:`landing_truth`) is computed when not given and the dataset
    has ground truth; without ground truth the scores hold only the detection counts.
    A ``max_height_sigma`` in ``landing`` needs a map with a height variance.
    """
    result = run(data, _landing_spec(mapper, params, landing))
    return _detect(data, result, landing, truth, label or str(dict(params or {})))


def score_landing(dataset: Registered, mapper: str | type[Mapper],
                  params: Mapping[str, object] | None,
                  landing_params: LandingSettings) -> dict[str, float]:
    """Scores of :func:`evaluate_landing` (precision, recall, ...) as a flat dict."""
    return evaluate_landing(dataset, mapper, params, landing_params).scores


def _grid_rows(cls: type[Mapper]) -> list[dict[str, object]]:
    """At most :data:`GRID_ROWS` rows of ``cls``'s settings grid, evenly spaced."""
    grid = cls.settings_grid
    rows = [dict(zip(grid, values, strict=True)) for values in itertools.product(*grid.values())]
    if len(rows) > GRID_ROWS:
        rows = [rows[round(i * (len(rows) - 1) / (GRID_ROWS - 1))] for i in range(GRID_ROWS)]
    return rows


def landing_param_sets(terrain: str, extra: Sequence[type[Mapper]] = ()) -> list[ParamSet]:
    """(label, mapper, params) to run on ``terrain``: chapter 4, then the sweep rows, then
    the rows of each ``extra`` mapper's settings grid."""
    out: list[ParamSet] = [(f"ch4 {name}", name, dict(p))
                           for name, p in mapper_params(terrain).items()]
    for name, (table, rows) in SWEEP_ROWS.items():
        out += [(f"5.{table} row {r}", name, dict(SWEEPS[table]["rows"][r][0])) for r in rows]
    for cls in extra:
        out += [(f"grid row {i}", cls, row) for i, row in enumerate(_grid_rows(cls))]
    return out


def _row(run: LandingRun, params: Mapping[str, object]) -> JSONDict:
    best = run.detection.sites.head(1)
    landing = run.landing
    return {"terrain": run.terrain, "mapper": run.map_run.info.mapper, "param_set": run.label,
            "params": ", ".join(f"{k}={v}" for k, v in params.items()),
            "basis_functions": run.map_run.mapper.basis_functions, **run.scores,
            "best_x": float(best["x"].iloc[0]) if len(best) else float("nan"),
            "best_y": float(best["y"].iloc[0]) if len(best) else float("nan"),
            "radius_m": landing.radius, "keep_out_m": landing.keep_out,
            "max_height_sigma_m": (float("nan") if landing.max_height_sigma is None
                                   else landing.max_height_sigma),
            "bound": ("" if landing.max_height_sigma is None
                      else f"sigma <= {landing.max_height_sigma:.3g} m")}


def _evaluations(data: Registered, job: ParamSet, landing: LandingSettings, *,
                 truth: Centres | None, sigma: bool) -> list[LandingRun]:
    """The map of one parameter set, and with ``sigma`` (a map with a height variance) the
    same map again under the sigma bound :data:`SIGMA_OF_OBSTACLE` of the obstacle height."""
    label, mapper, params = job
    found = evaluate_landing(data, mapper, params, landing, truth=truth, label=label)
    if not sigma or VARIANCE not in found.map_run.mapper.layers:
        return [found]
    bound = landing.replace(max_height_sigma=SIGMA_OF_OBSTACLE * landing.obstacle_height)
    return [found, _detect(data, found.map_run, bound, truth,
                           f"{label}, sigma <= {bound.max_height_sigma:.3g} m")]


def landing_table(datasets: Sequence[Registered],
                  landing: Mapping[str, LandingSettings] | None = None, *,
                  plugins: bool = False, extra: Sequence[type[Mapper]] = (),
                  sigma: bool = True, progress: bool = True
                  ) -> tuple[pd.DataFrame, list[LandingRun]]:
    """One row per terrain x mapper x parameter set (:func:`landing_param_sets`, with the
    settings grids of the ``extra`` mappers and, with ``plugins``, of every installed 2D
    plugin) and, with ``sigma``, one more per map with a height variance under the sigma
    bound (``max_height_sigma_m``, ``bound``).

    ``landing`` maps terrain names to parameters (default: :func:`landing_params`).
    The truth is computed once per terrain.
    """
    more = tuple(dict.fromkeys((*extra, *(registry.plugins(dims=2) if plugins else ()))))
    jobs = [(d, *s) for d in datasets for s in landing_param_sets(d.source.name, more)]
    rows, runs, truths = [], [], {}
    for data, label, mapper, params in progress_bar(jobs, desc="landing", unit="map",
                                            disable=not progress):
        name = data.source.name
        chosen = (landing or {}).get(name) or landing_params(name)
        if name not in truths and ground_truth(data) is not None:
            truths[name] = landing_truth(data, chosen)
        for found in _evaluations(data, (label, mapper, params), chosen,
                                  truth=truths.get(name), sigma=sigma):
            runs.append(found)
            rows.append(_row(found, params))
    return pd.DataFrame(rows), runs


def load_terrains(names: Sequence[str], data_dir: str | os.PathLike[str] = "data",
                  seed: int = 0, frames: int | None = None,
                  progress: bool = True) -> list[Registered]:
    """Simulate (when missing or stale) and register the named terrains, ``frames`` scans
    each."""
    return [terrain(name, data_dir, seed, frames)
            for name in progress_bar(names, desc="terrains", unit="terrain", disable=not progress)]


def landing_summary(table: pd.DataFrame) -> pd.DataFrame:
    """Mean scores per terrain and mapper (and height sigma ``bound``, when the table has
    one) over the parameter sets of :func:`landing_table`."""
    scores = ["precision", "area_precision", "recall", "recall_known", "detected_area_m2",
              "safe_area_m2"]
    missing = sorted({"terrain", "mapper", *scores} - set(table.columns))
    if missing:
        raise ParameterError(f"landing summary: table lacks columns {', '.join(missing)}")
    keys = ["terrain", "mapper", *(["bound"] if "bound" in table else [])]
    return table.groupby(keys, sort=False)[scores].mean().reset_index()


def write_landing_table(table: pd.DataFrame, out_dir: str | os.PathLike[str],
                        overwrite: bool = False) -> Path:
    """Write ``out_dir/table_landing.csv`` (atomic; refuses to overwrite by default)."""
    return write_csv(table, out_dir, "table_landing", overwrite)
