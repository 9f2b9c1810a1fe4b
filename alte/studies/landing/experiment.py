"""Landing-zone experiments: map a terrain, detect sites, score them against the truth.

Data flow: a registered terrain (:func:`alte.studies.experiments.terrain`) ->
:func:`alte.pipeline.run` (the 2D map) -> :func:`rasterise` over the control volume ->
:func:`detect_sites` -> scores
against :func:`truth_centres` of the same raster. :func:`landing_table` gives one row
per terrain x mapper x parameter set: the chapter 4 parameters of the terrain and two
rows of each chapter 5 sweep (:data:`SWEEP_ROWS`), written by
:func:`write_landing_table` as ``table_landing.csv``.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from alte.errors import MetricsError, ParameterError
from alte.pipeline import MapRun, MapSpec, Registered, run
from alte.progress import bar as progress_bar
from alte.studies.analysis.tables import write_csv
from alte.studies.experiments import ground_truth, terrain
from alte.studies.landing.detect import Centres, Detection, detect_sites
from alte.studies.landing.params import LandingParams, landing_params
from alte.studies.landing.raster import Grid, rasterise
from alte.studies.landing.truth import score_detection, truth_centres
from alte.studies.thesis.numbers import SWEEPS, mapper_params
from alte.types import JSONDict

__all__ = ["LANDING_MAPPERS", "SWEEP_ROWS", "LandingRun", "evaluate_landing", "landing_grid",
           "landing_param_sets", "landing_summary", "landing_table", "landing_truth",
           "load_terrains", "score_landing", "write_landing_table"]

#: The 2D mappers a landing map is made with (thesis 1.2: the landing case is 2D).
LANDING_MAPPERS = ("quadtree", "alte2d")
#: Rows of the chapter 5 sweeps run besides the chapter 4 parameters: table 5.7
#: (Quadtree max_points 100 and 500) and table 5.9 (2D-ALTE rows 1 and 4).
SWEEP_ROWS: dict[str, tuple[int, tuple[int, ...]]] = {"quadtree": (7, (1, 4)),
                                                      "alte2d": (9, (0, 4))}


@dataclass(eq=False)
class LandingRun:
    """One map with its detected sites, the truth it was scored on and the scores."""

    terrain: str
    label: str
    landing: LandingParams
    map_run: MapRun
    detection: Detection
    truth: Centres | None
    scores: dict[str, float]


def landing_grid(data: Registered, params: LandingParams) -> Grid:
    """The raster over the input's control volume (its points' extent when it has none)."""
    box = data.spec.crop if data.spec.crop is not None else data.bounds()
    return Grid.from_bounds(box.array(), params.step)


def landing_truth(data: Registered, params: LandingParams) -> Centres:
    """Truly safe centres of a simulated terrain on :func:`landing_grid`."""
    truth = ground_truth(data)
    if truth is None:
        raise MetricsError(f"landing truth: {data.source.path} has no ground truth "
                           "(real recordings cannot be scored)")
    return truth_centres(truth.surface, landing_grid(data, params), params,
                         z_start=float(truth.bounds.hi[2]))


def evaluate_landing(data: Registered, mapper: str, params: Mapping[str, object] | None,
                     landing: LandingParams, *, truth: Centres | None = None,
                     label: str = "") -> LandingRun:
    """Map ``data`` with ``mapper``/``params``, detect sites and score them when truth exists.

    ``truth`` (from :func:`landing_truth`) is computed when not given and the dataset
    has ground truth; without ground truth the scores hold only the detection counts.
    """
    if mapper not in LANDING_MAPPERS:
        raise ParameterError(f"landing: mapper {mapper!r} is not a 2D mapper; use one of "
                             f"{', '.join(LANDING_MAPPERS)}")
    result = run(data, MapSpec(mapper, dict(params or {})))
    grid = landing_grid(data, landing)
    detection = detect_sites(rasterise(result.mapper.cells(), grid), grid, landing)
    if truth is None and ground_truth(data) is not None:
        truth = landing_truth(data, landing)
    if truth is not None:
        scores = score_detection(detection, truth, landing)
    else:
        scores = {"sites": len(detection.sites), "chosen": len(detection.chosen)}
    return LandingRun(data.source.name, label or str(dict(params or {})), landing, result,
                      detection, truth, scores)


def score_landing(dataset: Registered, mapper: str, params: Mapping[str, object] | None,
                  landing_params: LandingParams) -> dict[str, float]:
    """Scores of :func:`evaluate_landing` (precision, recall, ...) as a flat dict."""
    return evaluate_landing(dataset, mapper, params, landing_params).scores


def landing_param_sets(terrain: str) -> list[tuple[str, str, dict[str, float]]]:
    """(label, mapper, params) to run on ``terrain``: chapter 4, then the sweep rows."""
    out = [(f"ch4 {name}", name, p) for name, p in mapper_params(terrain).items()]
    for name, (table, rows) in SWEEP_ROWS.items():
        out += [(f"5.{table} row {r}", name, dict(SWEEPS[table]["rows"][r][0])) for r in rows]
    return out


def _row(run: LandingRun, mapper: str, params: Mapping[str, float],
         landing: LandingParams) -> JSONDict:
    best = run.detection.sites.head(1)
    return {"terrain": run.terrain, "mapper": mapper, "param_set": run.label,
            "params": ", ".join(f"{k}={v}" for k, v in params.items()),
            "basis_functions": run.map_run.mapper.basis_functions, **run.scores,
            "best_x": float(best["x"].iloc[0]) if len(best) else float("nan"),
            "best_y": float(best["y"].iloc[0]) if len(best) else float("nan"),
            "radius_m": landing.radius, "keep_out_m": landing.keep_out}


def landing_table(datasets: Sequence[Registered],
                  landing: Mapping[str, LandingParams] | None = None, *,
                  progress: bool = True) -> tuple[pd.DataFrame, list[LandingRun]]:
    """One row per terrain x mapper x parameter set (:func:`landing_param_sets`).

    ``landing`` maps terrain names to parameters (default: :func:`landing_params`).
    The truth is computed once per terrain.
    """
    jobs = [(d, *s) for d in datasets for s in landing_param_sets(d.source.name)]
    rows, runs, truths = [], [], {}
    for data, label, mapper, params in progress_bar(jobs, desc="landing", unit="map",
                                            disable=not progress):
        name = data.source.name
        chosen = (landing or {}).get(name) or landing_params(name)
        if name not in truths and ground_truth(data) is not None:
            truths[name] = landing_truth(data, chosen)
        found = evaluate_landing(data, mapper, params, chosen, truth=truths.get(name),
                                 label=label)
        runs.append(found)
        rows.append(_row(found, mapper, params, chosen))
    return pd.DataFrame(rows), runs


def load_terrains(names: Sequence[str], data_dir: str | os.PathLike[str] = "data",
                  seed: int = 0, frames: int | None = None,
                  progress: bool = True) -> list[Registered]:
    """Simulate (when missing or stale) and register the named terrains, ``frames`` scans
    each."""
    return [terrain(name, data_dir, seed, frames)
            for name in progress_bar(names, desc="terrains", unit="terrain", disable=not progress)]


def landing_summary(table: pd.DataFrame) -> pd.DataFrame:
    """Mean scores per terrain and mapper over the parameter sets of :func:`landing_table`."""
    scores = ["precision", "area_precision", "recall", "recall_known", "detected_area_m2",
              "safe_area_m2"]
    missing = sorted({"terrain", "mapper", *scores} - set(table.columns))
    if missing:
        raise ParameterError(f"landing summary: table lacks columns {', '.join(missing)}")
    return table.groupby(["terrain", "mapper"], sort=False)[scores].mean().reset_index()


def write_landing_table(table: pd.DataFrame, out_dir: str | os.PathLike[str],
                        overwrite: bool = False) -> Path:
    """Write ``out_dir/table_landing.csv`` (atomic; refuses to overwrite by default)."""
    return write_csv(table, out_dir, "table_landing", overwrite)
