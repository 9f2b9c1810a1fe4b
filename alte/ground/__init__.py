"""Ground and obstacles: the ground filters of the field (SMRF, CSF), the thesis' MSAC
ground plane, and Euclidean obstacle clusters (thesis 3.13) measured from either."""

from alte.ground.clustering import OBSTACLE_COLUMNS, euclidean_clusters, obstacle_map
from alte.ground.filters import GroundResult, filter_ground
from alte.ground.obstacles import Obstacles, find_obstacles
from alte.ground.plane import (
    PlaneFit,
    fit_plane_msac,
    fit_plane_open3d,
    height_above,
    obstacle_mask,
)
from alte.ground.settings import DEFAULT_METHOD, DEFAULT_SETTINGS, METHODS, ground_settings

__all__ = [
    "DEFAULT_METHOD",
    "DEFAULT_SETTINGS",
    "METHODS",
    "OBSTACLE_COLUMNS",
    "GroundResult",
    "Obstacles",
    "PlaneFit",
    "euclidean_clusters",
    "filter_ground",
    "find_obstacles",
    "fit_plane_msac",
    "fit_plane_open3d",
    "ground_settings",
    "height_above",
    "obstacle_map",
    "obstacle_mask",
]
