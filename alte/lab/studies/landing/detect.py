"""Landing-site detection on a height raster: feasible centres, then ranked sites.

A pixel is a *feasible centre* when the disk of ``radius + margin`` around it is
known and planar (:func:`alte.lab.studies.landing.raster.plane_features`) and no obstacle lies
within ``keep_out`` (distance transforms of the unknown and obstacle masks, so every
test is one vectorized image operation). Unknown pixels are never ground: the thesis
notes that unknown space "looks the same as ground-level regions" in both 2D maps
(4.1.4), so they are excluded explicitly. A *site* is a connected component of
feasible centres (8-connected); its centre is the pixel with the best clearance and
flatness, and sites are ranked by a score that weighs clearance, flatness and area
equally (each term in [0, 1], see :func:`rank_sites`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd
from numpy.typing import NDArray
from scipy import ndimage

from alte.errors import ParameterError
from alte.ground.surface import ground_obstacles, planar, plane_features
from alte.lab.studies.landing.params import LandingSettings
from alte.lab.studies.landing.raster import RasterGeometry

__all__ = ["SITE_COLUMNS", "Centres", "Detection", "detect_sites", "feasible_centres",
           "map_obstacles", "rank_sites"]

#: Columns of the site table, best site first.
SITE_COLUMNS = ("rank", "x", "y", "height", "area_m2", "clearance_m", "slope_deg",
                "roughness_m", "score", "chosen")


@dataclass(frozen=True)
class Centres:
    """Per pixel: ``feasible`` site centre, distances (m) to the nearest unknown and
    obstacle pixel, the window plane's ``slope_deg``/``roughness`` and the masks used."""

    feasible: NDArray[np.bool_]
    known_dist: NDArray[np.float64]
    obstacle_dist: NDArray[np.float64]
    slope_deg: NDArray[np.float64]
    roughness: NDArray[np.float64]
    obstacle: NDArray[np.bool_]


@dataclass(frozen=True)
class Detection:
    """Detected landing sites on one raster: the per-pixel tests and the ranked sites."""

    grid: RasterGeometry
    height: NDArray[np.float64]
    centres: Centres
    sites: pd.DataFrame

    @property
    def chosen(self) -> pd.DataFrame:
        """The sites chosen for landing (the ``max_sites`` best ranked)."""
        return self.sites[self.sites["chosen"]]


def _distance_to(mask: NDArray[np.bool_], step: float, pad_true: bool) -> NDArray[np.float64]:
    """Distance (m) from every pixel centre to the nearest ``mask`` pixel (inf if none).

    ``pad_true`` counts the outside of the raster as ``mask`` (unknown space)."""
    if pad_true:
        mask = np.pad(mask, 1, constant_values=True)
    if not mask.any():
        return np.full(mask.shape, np.inf)
    dist = ndimage.distance_transform_edt(~mask, sampling=step)
    return dist[1:-1, 1:-1] if pad_true else dist


def map_obstacles(height: NDArray[np.float64], grid: RasterGeometry, params: LandingSettings,
                  ground: float | None = None, seed: int = 0) -> NDArray[np.bool_]:
    """Known pixels more than ``obstacle_height`` above or below the ground.

    ``ground`` is a height (m); None fits the ground plane with MSAC (thesis 2.1.4)
    to the known pixels (:func:`alte.ground.surface.ground_obstacles`).
    """
    return ground_obstacles(height, grid.centers(), params.obstacle_height, ground, seed)


def feasible_centres(height: NDArray[np.float64], obstacle: NDArray[np.bool_], step: float,
                     params: LandingSettings) -> Centres:
    """Test every pixel as a site centre (module docstring); NaN heights are unknown."""
    height = np.asarray(height, dtype=np.float64)
    obstacle = np.asarray(obstacle, dtype=bool)
    if height.ndim != 2 or obstacle.shape != height.shape:
        raise ParameterError(f"landing: height {height.shape} and obstacle {obstacle.shape} "
                             "must be 2D arrays of one shape")
    known = np.isfinite(height)
    known_dist = _distance_to(~known, step, pad_true=True)
    obstacle_dist = _distance_to(obstacle & known, step, pad_true=False)
    feats = plane_features(height, step, params.disk)
    flat = planar(feats, params.surface)
    feasible = known & flat & (known_dist > params.disk) & (obstacle_dist > params.keep_out)
    return Centres(feasible, known_dist, obstacle_dist, feats.slope_deg, feats.roughness,
                   obstacle & known)


def _pixel_terms(centres: Centres, params: LandingSettings,
                 ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Room (gap from the footprint to the nearest obstacle or unknown pixel, over twice
    ``keep_out``; not capped) and flatness in [0, 1] per pixel."""
    room = np.minimum(centres.obstacle_dist, centres.known_dist) - params.radius
    flat = 1.0 - 0.5 * (centres.slope_deg / params.max_slope_deg
                        + centres.roughness / params.max_roughness)
    return room / (2.0 * params.keep_out), np.clip(np.nan_to_num(flat, nan=0.0), 0.0, 1.0)


def rank_sites(centres: Centres, height: NDArray[np.float64], grid: RasterGeometry,
               params: LandingSettings) -> pd.DataFrame:
    """Sites = 8-connected components of feasible centres, best first (:data:`SITE_COLUMNS`).

    Per site the centre is the pixel maximising room + flatness (room: gap from the
    footprint to the nearest obstacle or unknown pixel over twice ``keep_out``, so the
    most open point wins); the score is the mean of three terms in [0, 1] there: room
    capped at 1, flatness (1 - mean of slope and roughness over their limits) and area
    (feasible-centre area over the disk area, capped at 1).
    """
    labels, count = ndimage.label(centres.feasible, structure=np.ones((3, 3), dtype=bool))
    if count == 0:
        return pd.DataFrame({c: pd.Series(dtype=bool if c == "chosen" else float)
                             for c in SITE_COLUMNS})
    room, flat = _pixel_terms(centres, params)
    index = np.arange(1, count + 1)
    pos = np.array(ndimage.maximum_position(room + flat, labels, index)).reshape(-1, 2)
    rows, cols = pos[:, 0], pos[:, 1]
    area = ndimage.sum_labels(centres.feasible, labels, index) * grid.step**2
    area_term = np.minimum(area / (np.pi * params.disk**2), 1.0)
    xs, ys = grid.axes()
    table = pd.DataFrame({
        "x": xs[cols], "y": ys[rows], "height": height[rows, cols], "area_m2": area,
        "clearance_m": centres.obstacle_dist[rows, cols] - params.radius,
        "slope_deg": centres.slope_deg[rows, cols], "roughness_m": centres.roughness[rows, cols],
        "score": (np.minimum(room[rows, cols], 1.0) + flat[rows, cols] + area_term) / 3.0,
    })
    table = table.sort_values(["score", "area_m2"], ascending=False, kind="stable")
    table.insert(0, "rank", np.arange(1, count + 1))
    table["chosen"] = table["rank"] <= params.max_sites
    return table.reset_index(drop=True)[list(SITE_COLUMNS)]


def detect_sites(height: NDArray[np.float64], grid: RasterGeometry, params: LandingSettings,
                 ground: float | None = None, seed: int = 0) -> Detection:
    """Landing sites on a height raster (NaN = unknown); ``ground`` as in :func:`map_obstacles`."""
    height = np.asarray(height, dtype=np.float64)
    if height.shape != grid.shape:
        raise ParameterError(f"landing: height raster {height.shape} does not match the grid "
                             f"{grid.shape}")
    if not np.isclose(grid.step, params.step):
        raise ParameterError(f"landing: grid step {grid.step} m differs from the parameter "
                             f"step={params.step} m")
    obstacle = map_obstacles(height, grid, params, ground, seed)
    centres = feasible_centres(height, obstacle, grid.step, params)
    return Detection(grid, height, centres, rank_sites(centres, height, grid, params))
