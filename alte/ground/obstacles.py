"""Obstacles on real terrain: what the ground filter rejects, clustered, measured from the
bare earth under it (the obstacle map of thesis 3.3.1 with a local ground for its plane).

The thesis separates obstacles from one MSAC plane, which holds on a flat site; on real
terrain a hill or a slope rises above any one plane. :func:`find_obstacles` takes the
ground stage's filter instead (:func:`alte.ground.filters.filter_ground`): a point is an
obstacle point when the filter rejects it and it stands more than ``min_height`` above
the bare earth under it; Euclidean clusters of those points (``tolerance`` m) are the
obstacles, each with its height above the bare earth (:func:`obstacle_map`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from alte.errors import ParameterError
from alte.ground.clustering import euclidean_clusters, obstacle_map
from alte.ground.filters import GroundResult, filter_ground

__all__ = ["Obstacles", "find_obstacles"]


@dataclass(frozen=True, eq=False)
class Obstacles:
    """Per point its cluster label (-1: not an obstacle point), the ground run behind it
    and the obstacle map (one row per cluster; :data:`alte.ground.OBSTACLE_COLUMNS`)."""

    labels: NDArray[np.int64]
    ground: GroundResult
    table: pd.DataFrame


def find_obstacles(points: NDArray[np.float64], ground: GroundResult | None = None, *,
                   min_height: float = 0.3, tolerance: float = 0.5,
                   min_size: int = 1) -> Obstacles:
    """Obstacles of ``points`` (module docstring); ``ground`` is a filter run on the same
    points (None: the ground stage's default run here)."""
    if not (np.isfinite(min_height) and min_height >= 0):
        raise ParameterError(f"find_obstacles: min_height={min_height!r} must be >= 0 m")
    pts = np.asarray(points, np.float64)
    run = ground if ground is not None else filter_ground(pts)
    if len(run.ground) != len(pts):
        raise ParameterError(f"find_obstacles: the ground run has {len(run.ground)} points, "
                             f"the cloud {len(pts)}")
    if run.height is None:
        raise ParameterError(f"find_obstacles: ground {run.method} gives no bare earth to "
                             "measure obstacles from; use smrf, morph or plane")
    above = pts[:, 2] - run.height
    candidate = ~run.ground & (np.nan_to_num(above, nan=-np.inf) > min_height)
    labels = np.full(len(pts), -1, np.int64)
    if candidate.any():
        labels[candidate] = euclidean_clusters(pts[candidate], tolerance, min_size)
    return Obstacles(labels, run, obstacle_map(pts, labels, run.height))
