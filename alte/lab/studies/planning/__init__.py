"""Path planning over 3D maps (thesis ch. 6: "using the maps alongside a path planning algorithm").

Data flows one way: a 3D map (Octomap or 3D-ALTE cells) -> :class:`PlanningMap` ->
a uniform lattice classified occupied / free / unknown and inflated by a clearance
radius (:mod:`alte.lab.studies.planning.lattice`) -> 26-neighbour graph and Dijkstra
(:mod:`alte.lab.studies.planning.search`) -> the path scored against the true mesh
(:mod:`alte.lab.studies.planning.score`); :mod:`alte.lab.studies.planning.experiment` runs it per
terrain,
mapper and unknown-space policy and makes ``table_planning``.
"""

from alte.lab.studies.planning.experiment import (
    PLANNING_CASES,
    PlanningCase,
    TerrainPlans,
    plan_maps,
    planning_case,
    planning_experiment,
    planning_rows,
    write_planning_table,
)
from alte.lab.studies.planning.lattice import (
    FREE,
    OCCUPIED,
    POLICIES,
    UNKNOWN,
    Lattice,
    PlanningMap,
    blocked_nodes,
    classify,
    locate,
    near_boxes,
    planning_map,
)
from alte.lab.studies.planning.score import PathScore, densify, score_path
from alte.lab.studies.planning.search import OFFSETS, PlanResult, lattice_graph, plan_path

__all__ = [
    "FREE",
    "OCCUPIED",
    "OFFSETS",
    "PLANNING_CASES",
    "POLICIES",
    "UNKNOWN",
    "Lattice",
    "PathScore",
    "PlanResult",
    "PlanningCase",
    "PlanningMap",
    "TerrainPlans",
    "blocked_nodes",
    "classify",
    "densify",
    "lattice_graph",
    "locate",
    "near_boxes",
    "plan_maps",
    "plan_path",
    "planning_case",
    "planning_experiment",
    "planning_map",
    "planning_rows",
    "score_path",
    "write_planning_table",
]
