"""Ground and obstacles: the MSAC ground plane and Euclidean obstacle clusters (thesis 3.13)."""

from alte.ground.clustering import OBSTACLE_COLUMNS, euclidean_clusters, obstacle_map
from alte.ground.plane import (
    PlaneFit,
    fit_plane_msac,
    fit_plane_open3d,
    height_above,
    obstacle_mask,
)

__all__ = [
    "OBSTACLE_COLUMNS",
    "PlaneFit",
    "euclidean_clusters",
    "fit_plane_msac",
    "fit_plane_open3d",
    "height_above",
    "obstacle_map",
    "obstacle_mask",
]
