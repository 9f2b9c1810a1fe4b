"""Names of :mod:`alte.ground`, loaded on first use (``lazy_loader``)."""

from .clustering import OBSTACLE_COLUMNS, euclidean_clusters, obstacle_map
from .filters import GroundResult, filter_ground
from .obstacles import Obstacles, find_obstacles
from .plane import (
    PlaneFit,
    fit_plane_msac,
    fit_plane_open3d,
    height_above,
    obstacle_mask,
)
from .settings import DEFAULT_METHOD, DEFAULT_SETTINGS, METHODS, ground_settings

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
