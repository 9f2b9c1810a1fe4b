"""Landing-zone detection on 2D maps (Quadtree, 2D-ALTE, 2D plugins), scored against truth.

Thesis 1.2 defines a landing zone as "any planar site, free of obstacles, with a clear
approach path, and with an area big enough for the vehicle to land". Here a 2D map is
rasterised (:mod:`alte.lab.studies.landing.raster`), every pixel is tested as a site centre and
connected feasible centres become ranked sites (:mod:`alte.lab.studies.landing.detect`); the same
tests on the simulator's true surface, plus "no object other than ground", give the
truly safe centres the detection is scored against (:mod:`alte.lab.studies.landing.truth`), per
terrain, mapper and parameter set (:mod:`alte.lab.studies.landing.experiment`).
"""

from alte.lab.studies.landing.detect import (
    SITE_COLUMNS,
    Centres,
    Detection,
    detect_sites,
    feasible_centres,
    map_obstacles,
    rank_sites,
)
from alte.lab.studies.landing.experiment import (
    GRID_ROWS,
    SWEEP_ROWS,
    LandingRun,
    evaluate_landing,
    landing_grid,
    landing_param_sets,
    landing_summary,
    landing_table,
    landing_truth,
    load_terrains,
    score_landing,
    write_landing_table,
)
from alte.lab.studies.landing.params import (
    LAB,
    QUADROTOR,
    SIGMA_OF_OBSTACLE,
    LandingSettings,
    landing_params,
)
from alte.lab.studies.landing.raster import (
    PlaneFeatures,
    RasterGeometry,
    plane_features,
    rasterise,
    rasterise_sigma,
)
from alte.lab.studies.landing.truth import (
    GROUND_CLASSES,
    object_footprints,
    score_detection,
    top_surface,
    truth_centres,
)

__all__ = [
    "GRID_ROWS",
    "GROUND_CLASSES",
    "LAB",
    "QUADROTOR",
    "SIGMA_OF_OBSTACLE",
    "SITE_COLUMNS",
    "SWEEP_ROWS",
    "Centres",
    "Detection",
    "LandingRun",
    "LandingSettings",
    "PlaneFeatures",
    "RasterGeometry",
    "detect_sites",
    "evaluate_landing",
    "feasible_centres",
    "landing_grid",
    "landing_param_sets",
    "landing_params",
    "landing_summary",
    "landing_table",
    "landing_truth",
    "load_terrains",
    "map_obstacles",
    "object_footprints",
    "plane_features",
    "rank_sites",
    "rasterise",
    "rasterise_sigma",
    "score_detection",
    "score_landing",
    "top_surface",
    "truth_centres",
    "write_landing_table",
]
