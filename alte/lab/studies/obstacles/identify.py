"""Which true obstacles a map shows, which of its obstacles are not there, and how tall.

The map becomes a height raster on the truth's grid (:func:`map_raster`): a 2D map
gives each pixel the height of the cell holding its centre (as the landing study
does); a 3D map gives each pixel the highest centre of the occupied cells whose x/y
square overlaps it (a voxel thinner than a pixel still marks it). The map's ground is
the median of its known pixels (the flat-ground datum a landing vehicle would take);
a pixel is a *map obstacle* when it stands more than ``min_height`` above that, and
for a 3D map more than its top cell's edge too (a voxel map states a height only to
within a cell: ground points straddling a voxel boundary make steps of one edge).

Scores (:func:`identify`): a true obstacle is *found* when a map obstacle pixel lies
on its visible footprint or within ``slack`` pixels of it (``recall`` = found / true
obstacles); a map obstacle (an 8-connected component of obstacle pixels) is *there*
when it touches the footprint of any simulator object, tall or not (``precision`` =
there / map obstacles; ``area_precision`` the same share of obstacle pixels). The
height error of a found obstacle is its height above the map's ground as the map
shows it (the highest known pixel of its footprint) minus its true height above the
true ground: negative where a coarse cell averages it away.
"""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np
import pandas as pd
from numpy.typing import NDArray
from scipy import ndimage

from alte.lab.studies.experiments import ground_truth
from alte.lab.studies.landing.raster import RasterGeometry
from alte.lab.studies.obstacles.truth import ObstacleSettings, TrueObstacles, terrain_obstacles
from alte.mappers.base import Cells
from alte.pipeline import Registered

__all__ = [
    "OBJECT_COLUMNS",
    "SCORE_COLUMNS",
    "MapRaster",
    "ObstacleScores",
    "identify",
    "map_raster",
    "obstacle_scores",
]

#: The scores of one map as table columns (:meth:`ObstacleScores.flat`).
SCORE_COLUMNS = ("obstacles_true", "obstacles_found", "obstacles_map", "obstacles_map_there",
                 "obstacle_recall", "obstacle_precision", "obstacle_area_precision",
                 "obstacle_height_error_m", "obstacle_height_bias_m", "obstacle_ground_m")
#: Columns of :attr:`ObstacleScores.objects` (one row per true obstacle).
OBJECT_COLUMNS = ("object_id", "object", "cls", "true_height_m", "found", "map_height_m",
                  "height_error_m")
_EIGHT = np.ones((3, 3), dtype=bool)


def _spans(lo: NDArray[np.float64], hi: NDArray[np.float64], origin: float, step: float,
           count: int, *, centres: bool) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """First and last pixel of each interval [lo, hi): those whose centre it holds
    (``centres``), else those it overlaps; clipped to the raster, empty when last < first."""
    a, b = (lo - origin) / step, (hi - origin) / step
    if centres:
        first, last = np.ceil(a - 0.5), np.ceil(b - 0.5) - 1
    else:
        first, last = np.floor(a + 1e-9), np.ceil(b - 1e-9) - 1
    return (np.clip(first, 0, count).astype(np.int64),
            np.clip(last, -1, count - 1).astype(np.int64))


@numba.njit(cache=True)
def _max_into(
    out: NDArray[np.float64], rows: tuple[NDArray[np.int64], NDArray[np.int64]],
    cols: tuple[NDArray[np.int64], NDArray[np.int64]], values: NDArray[np.float64],
    nx: int,
) -> None:
    """``out[r * nx + c] = max(out, value)`` over each cell's pixel block (rows and columns
    first to last), NaN winning as in ``np.maximum``."""
    for i in range(values.shape[0]):
        v = values[i]
        for r in range(rows[0][i], rows[1][i] + 1):
            for c in range(cols[0][i], cols[1][i] + 1):
                if v > out[r * nx + c] or np.isnan(v):
                    out[r * nx + c] = v


def _paint(centers: NDArray[np.float64], half: NDArray[np.float64],
           values: NDArray[np.float64], grid: RasterGeometry, centres: bool) -> NDArray[np.float64]:
    """Per pixel, the largest of ``values`` over the cells covering it (NaN: none)."""
    ny, nx = grid.shape
    out = np.full(ny * nx, -np.inf)
    cols = _spans(centers[:, 0] - half[:, 0], centers[:, 0] + half[:, 0], grid.origin[0],
                  grid.step, nx, centres=centres)
    rows = _spans(centers[:, 1] - half[:, 1], centers[:, 1] + half[:, 1], grid.origin[1],
                  grid.step, ny, centres=centres)
    _max_into(out, rows, cols, np.ascontiguousarray(values, dtype=np.float64), nx)
    return np.where(np.isfinite(out), out, np.nan).reshape(grid.shape)


@dataclass(frozen=True)
class MapRaster:
    """A map on the truth's raster: ``height`` (m; NaN where the map shows nothing) and
    ``floor``, the level a pixel's top must clear for the map to state an obstacle there:
    its height minus ``min_height`` for a 2D map; for a 3D map, whose cells state a
    height only to within their edge, the highest occupied cell centre minus the larger
    of ``min_height`` and that cell's edge."""

    height: NDArray[np.float64]
    floor: NDArray[np.float64]


def map_raster(cells: Cells, dims: int, grid: RasterGeometry, min_height: float) -> MapRaster:
    """The map as a :class:`MapRaster` (see the module docstring)."""
    if dims == 2:
        keep = np.isfinite(cells.centers).all(axis=1)
        height = _paint(cells.centers[keep], cells.sizes[keep] / 2.0, cells.centers[keep, 2],
                        grid, centres=True)
        return MapRaster(height, height - min_height)
    keep = cells.occupied.astype(bool) & np.isfinite(cells.centers).all(axis=1)
    centers, half = cells.centers[keep], cells.sizes[keep] / 2.0
    height = _paint(centers, half, centers[:, 2], grid, centres=False)
    step = np.maximum(2.0 * half[:, 2], min_height)
    return MapRaster(height, _paint(centers, half, centers[:, 2] - step, grid, centres=False))


@dataclass(frozen=True)
class ObstacleScores:
    """One map's obstacle identification (module docstring): ``objects`` per true
    obstacle, the ``min_height`` that made them obstacles and the names of those
    ``hidden`` from above."""

    true: int
    found: int
    map_obstacles: int
    map_there: int
    recall: float
    precision: float
    area_precision: float
    height_error_m: float
    height_bias_m: float
    ground_m: float
    objects: pd.DataFrame
    min_height: float = float("nan")
    hidden: tuple[str, ...] = ()

    def flat(self) -> dict[str, float]:
        """The scalar scores as columns of a table row (:data:`SCORE_COLUMNS`)."""
        values = (self.true, self.found, self.map_obstacles, self.map_there, self.recall,
                  self.precision, self.area_precision, self.height_error_m,
                  self.height_bias_m, self.ground_m)
        return dict(zip(SCORE_COLUMNS, values, strict=True))


def _share(num: int, den: int) -> float:
    return float(num / den) if den else float("nan")


def _object_rows(truth: TrueObstacles, height: NDArray[np.float64], obstacle: NDArray[np.bool_],
                 ground: float) -> pd.DataFrame:
    flat_h = height.ravel()
    rows = []
    for i, (pixels, near) in enumerate(zip(truth.footprints, truth.near, strict=True)):
        found = bool(obstacle[near].any())
        seen = flat_h[pixels][np.isfinite(flat_h[pixels])]
        if not seen.size:
            seen = flat_h[near][obstacle[near]]
        shown = float(seen.max()) - ground if found and seen.size else float("nan")
        rows.append({"object_id": int(truth.ids[i]), "object": truth.names[i],
                     "cls": truth.classes[i], "true_height_m": float(truth.heights[i]),
                     "found": found, "map_height_m": shown,
                     "height_error_m": shown - float(truth.heights[i])})
    return pd.DataFrame(rows, columns=list(OBJECT_COLUMNS))


def identify(raster: MapRaster, truth: TrueObstacles) -> ObstacleScores:
    """Score the map ``raster`` (on ``truth.grid``) against ``truth``."""
    height = raster.height
    known = np.isfinite(height)
    ground = float(np.median(height[known])) if known.any() else float("nan")
    with np.errstate(invalid="ignore"):
        obstacle = known & (raster.floor > ground)
    labels, count = ndimage.label(obstacle, structure=_EIGHT)
    there = np.unique(labels.ravel()[truth.objects & obstacle.ravel()])
    objects = _object_rows(truth, height, obstacle.ravel(), ground)
    found = objects[objects["found"].astype(bool)]  # an empty column is of object dtype
    errors = found["height_error_m"].to_numpy(float)
    errors = errors[np.isfinite(errors)]
    return ObstacleScores(
        true=len(truth), found=len(found), map_obstacles=int(count),
        map_there=len(there), recall=_share(len(found), len(truth)),
        precision=_share(len(there), int(count)),
        area_precision=_share(int((truth.objects & obstacle.ravel()).sum()),
                              int(obstacle.sum())),
        height_error_m=float(np.abs(errors).mean()) if errors.size else float("nan"),
        height_bias_m=float(errors.mean()) if errors.size else float("nan"),
        ground_m=ground, objects=objects, min_height=truth.options.min_height,
        hidden=truth.hidden)


def obstacle_scores(data: Registered, cells: Cells, dims: int,
                    options: ObstacleSettings | None) -> ObstacleScores | None:
    """The map ``cells``' identification of the terrain's true obstacles
    (:mod:`alte.lab.studies.obstacles`); None without ``options`` or off a simulated terrain."""
    if options is None or ground_truth(data) is None:
        return None
    known = terrain_obstacles(str(data.source.path), options)
    return identify(map_raster(cells, dims, known.grid, options.min_height), known)
