"""Obstacle identification against the simulator's truth (thesis table 5.3, 5.1.1, ch. 6).

The thesis ranks obstacle identification first among the landing criteria (table 5.3:
"Quadtree Mid, 2D ALTE High") but had no truth to measure it with. Here every map of
the trade-off grid is scored against the simulator's objects:
:mod:`~alte.lab.studies.obstacles.truth` lists the true obstacles a landing UAV must see
(object ids, heights, visible footprints on a raster), :mod:`~alte.lab.studies.obstacles.identify`
turns a map into a height raster and scores it (recall, precision, height error of
every found obstacle), and :mod:`~alte.lab.studies.obstacles.tables` writes
``obstacles.csv`` and ``obstacle_objects.csv`` from the grid's rows.
"""

from alte.lab.studies.obstacles.identify import (
    OBJECT_COLUMNS,
    SCORE_COLUMNS,
    MapRaster,
    ObstacleScores,
    identify,
    map_raster,
    obstacle_scores,
)
from alte.lab.studies.obstacles.tables import (
    OBJECTS_COLUMN,
    OBSTACLE_COLUMNS,
    object_table,
    obstacle_columns,
    obstacles_table,
    setting_text,
    write_obstacle_tables,
)
from alte.lab.studies.obstacles.truth import (
    ObstacleSettings,
    TrueObstacles,
    obstacle_options,
    terrain_obstacles,
    true_obstacles,
)

__all__ = [
    "OBJECTS_COLUMN",
    "OBJECT_COLUMNS",
    "OBSTACLE_COLUMNS",
    "SCORE_COLUMNS",
    "MapRaster",
    "ObstacleScores",
    "ObstacleSettings",
    "TrueObstacles",
    "identify",
    "map_raster",
    "object_table",
    "obstacle_columns",
    "obstacle_options",
    "obstacle_scores",
    "obstacles_table",
    "setting_text",
    "terrain_obstacles",
    "true_obstacles",
    "write_obstacle_tables",
]
