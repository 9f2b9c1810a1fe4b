"""The experiments of thesis chapters 4 and 5, called by the chapter notebooks.

:mod:`~alte.studies.experiments` maps a terrain and measures the maps,
:mod:`~alte.studies.tables` builds tables 5.5-5.12 (comparison rule, trend checks,
CSV output), :mod:`~alte.studies.qualitative` tables 5.1-5.4 and
:mod:`~alte.plot.terrain` the chapter figures.
"""

from alte.plot.terrain import (
    add_terrain,
    cloud_figure,
    map_grid_figure,
    pose_figure,
    trajectory_figure,
)
from alte.studies.experiments import (
    BATCH_MAPPERS,
    CUBE_DOMAIN_MAPPERS,
    Dataset,
    MapRun,
    TruthOptions,
    flat_metrics,
    load_dataset,
    map_metrics,
    run_mapper,
    surface_from_scene,
    sweep,
)
from alte.studies.qualitative import (
    MEASURES,
    class_completeness,
    qualitative_inputs,
    qualitative_table,
)
from alte.studies.tables import (
    COMPARISON_TRENDS,
    SWEEP_TRENDS,
    THESIS_CRITERIA,
    best_row,
    comparison_scores,
    comparison_table,
    point_cloud_table,
    thesis_metrics,
    trend_table,
    write_table,
)

__all__ = [
    "BATCH_MAPPERS",
    "COMPARISON_TRENDS",
    "CUBE_DOMAIN_MAPPERS",
    "MEASURES",
    "SWEEP_TRENDS",
    "THESIS_CRITERIA",
    "Dataset",
    "MapRun",
    "TruthOptions",
    "add_terrain",
    "best_row",
    "class_completeness",
    "cloud_figure",
    "comparison_scores",
    "comparison_table",
    "flat_metrics",
    "load_dataset",
    "map_grid_figure",
    "map_metrics",
    "point_cloud_table",
    "pose_figure",
    "qualitative_inputs",
    "qualitative_table",
    "run_mapper",
    "surface_from_scene",
    "sweep",
    "thesis_metrics",
    "trajectory_figure",
    "trend_table",
    "write_table",
]
