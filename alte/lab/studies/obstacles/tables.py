"""Obstacle identification as table rows: the grid's columns, ``obstacles.csv`` and
``obstacle_objects.csv``.

A sweep run with obstacles on (:func:`obstacle_columns`) carries the scores as
``obstacle_*`` / ``obstacles_*`` columns, the true obstacles hidden from above as
``obstacles_hidden`` text and every obstacle's outcome as JSON (``obstacle_objects``).
:func:`obstacles_table` gives one row per map (terrain, mapper, setting, seed, recall,
precision, ...); :func:`object_table` one row per map and true obstacle, with the
simulator's object id and the height error of every found one.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import pandas as pd

from alte.lab.studies.analysis.tables import write_csv
from alte.lab.studies.obstacles.identify import OBJECT_COLUMNS, SCORE_COLUMNS, ObstacleScores
from alte.types import JSONDict

__all__ = ["OBJECTS_COLUMN", "OBSTACLE_COLUMNS", "object_table", "obstacle_columns",
           "obstacles_table", "setting_text", "write_obstacle_tables"]

#: The grid column holding every true obstacle's outcome as JSON.
OBJECTS_COLUMN = "obstacle_objects"
#: Columns of ``obstacles.csv``.
OBSTACLE_COLUMNS = ("terrain", "case", "mapper", "setting", "seed", "basis_functions", "recall",
                    "precision", "area_precision", "height_error_m", "height_bias_m",
                    "obstacles_true", "obstacles_found", "obstacles_map", "min_height_m",
                    "hidden")
_KEYS = ("terrain", "case", "mapper", "setting", "seed")


def obstacle_columns(scores: ObstacleScores | None) -> JSONDict:
    """A sweep row's obstacle columns (none without scores)."""
    if scores is None:
        return {}
    objects = scores.objects.replace({np.nan: None}).to_dict(orient="records")
    return {**scores.flat(), "obstacle_min_height_m": scores.min_height,
            "obstacles_hidden": ", ".join(scores.hidden),
            OBJECTS_COLUMN: json.dumps(objects, sort_keys=True)}


def setting_text(params: object) -> str:
    """A parameter setting (JSON text or mapping) as ``k=v, k=v``."""
    values = json.loads(params) if isinstance(params, str) and params.startswith("{") else params
    if not isinstance(values, dict):
        return str(values)
    return ", ".join(f"{k}={v:g}" if isinstance(v, float) else f"{k}={v}"
                     for k, v in sorted(values.items()))


def _scored(grid: pd.DataFrame) -> pd.DataFrame:
    """The rows of maps scored against at least one true obstacle."""
    if not {"obstacles_true", OBJECTS_COLUMN} <= set(grid.columns):
        return grid.iloc[0:0]
    return grid[grid["obstacles_true"].fillna(0) > 0]


def obstacles_table(grid: pd.DataFrame) -> pd.DataFrame:
    """One row per scored map of a trade-off grid (:data:`OBSTACLE_COLUMNS`)."""
    rows = _scored(grid)
    if rows.empty:
        return pd.DataFrame(columns=list(OBSTACLE_COLUMNS))
    out = pd.DataFrame({
        "terrain": rows["terrain"], "case": rows.get("case", pd.Series("", index=rows.index)),
        "mapper": rows["mapper"], "setting": [setting_text(p) for p in rows["params"]],
        "seed": rows["seed"], "basis_functions": rows["basis_functions"]})
    for column in SCORE_COLUMNS:
        out[column.removeprefix("obstacle_")] = rows[column]
    out["min_height_m"] = rows["obstacle_min_height_m"]
    out["hidden"] = rows["obstacles_hidden"]
    return out.reindex(columns=list(OBSTACLE_COLUMNS)).reset_index(drop=True)


def object_table(grid: pd.DataFrame) -> pd.DataFrame:
    """One row per scored map and true obstacle (map keys, then :data:`OBJECT_COLUMNS`)."""
    rows = _scored(grid)
    parts = []
    if rows.empty:
        return pd.DataFrame(columns=[*_KEYS, *OBJECT_COLUMNS])
    for record in rows.to_dict(orient="records"):
        objects = pd.DataFrame(json.loads(record[OBJECTS_COLUMN]), columns=list(OBJECT_COLUMNS))
        keys = {"terrain": record["terrain"], "case": record.get("case", ""),
                "mapper": record["mapper"], "setting": setting_text(record["params"]),
                "seed": record["seed"]}
        parts.append(objects.assign(**keys))
    return pd.concat(parts, ignore_index=True)[[*_KEYS, *OBJECT_COLUMNS]]


def write_obstacle_tables(grid: pd.DataFrame, tables_dir: str | os.PathLike[str], *,
                          overwrite: bool = True) -> list[Path]:
    """Write ``obstacles.csv`` and ``obstacle_objects.csv`` (nothing when no map was
    scored)."""
    table = obstacles_table(grid)
    if table.empty:
        return []
    return [write_csv(table, tables_dir, "obstacles", overwrite),
            write_csv(object_table(grid), tables_dir, "obstacle_objects", overwrite)]
