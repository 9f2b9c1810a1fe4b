"""The planning experiment: each navigation terrain x 3D mapper x unknown-space policy.

Start and goal per terrain are fixed points (:data:`PLANNING_CASES`) chosen so that
the straight line between them crosses obstacles below the flight altitude, where
the sensor looked: the planner must go around, under or over something. Each map is
built with the chapter 4 parameters (:func:`alte.lab.studies.thesis.numbers.mapper_params`),
planned on
with both policies, and every found path is scored against the true mesh.
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from alte.errors import ParameterError
from alte.lab.studies.analysis.tables import write_csv
from alte.lab.studies.experiments import ground_truth, terrain
from alte.lab.studies.planning.lattice import POLICIES, PlanningMap, planning_map
from alte.lab.studies.planning.score import PathScore, score_path
from alte.lab.studies.planning.search import PlanResult, plan_path
from alte.lab.studies.thesis.numbers import mapper_params
from alte.metrics import TrueSurface
from alte.pipeline import MapSettings, Registered, run
from alte.progress import bar as progress_bar
from alte.types import JSONDict

__all__ = ["PLANNING_CASES", "PlanningCase", "TerrainPlans", "plan_maps", "planning_case",
           "planning_experiment", "planning_rows", "write_planning_table"]


@dataclass(frozen=True)
class PlanningCase:
    """Start, goal, domain ``bounds`` (xmin, ymin, zmin, xmax, ymax, zmax), clearance, step (m)."""

    start: tuple[float, float, float]
    goal: tuple[float, float, float]
    bounds: tuple[float, float, float, float, float, float]
    clearance: float
    step: float

    @property
    def box(self) -> NDArray[np.float64]:
        return np.asarray(self.bounds, dtype=np.float64).reshape(2, 3)


#: Per terrain: urban scale (1 m clearance on a 1 m lattice, from the ground to the crop
#: box top) or lab scale (0.2 m clearance on a 0.1 m lattice over the control volume).
PLANNING_CASES: dict[str, PlanningCase] = {
    # West of the L-shaped building to east of the stepped pyramid, 5 m up.
    "sim_nav_1": PlanningCase((-34.0, 8.0, 5.0), (24.0, 12.0, 5.0),
                              (-45.0, -35.0, 0.0, 45.0, 35.0, 15.0), 1.0, 1.0),
    # Through both towers at 6 m (under the sky bridge, below the 8 m flight altitude).
    "sim_nav_2": PlanningCase((-34.0, 12.0, 6.0), (0.0, 12.0, 6.0),
                              (-40.0, -30.0, 0.0, 40.0, 30.0, 15.0), 1.0, 1.0),
    # From the canyon to the gap between the last two buoys, 0.5 m above the floor.
    "exp_nav_1": PlanningCase((1.5, 3.2, 0.5), (5.25, 1.8, 0.5),
                              (0.0, 0.0, 0.0, 8.0, 6.0, 2.5), 0.2, 0.1),
    # Past the low box and under/around the table, 0.6 m above the floor.
    "exp_nav_2": PlanningCase((1.6, 2.0, 0.6), (6.2, 3.8, 0.6),
                              (0.0, 0.0, 0.0, 8.0, 6.0, 2.5), 0.2, 0.1),
}


def planning_case(terrain: str) -> PlanningCase:
    """The start/goal/domain of ``terrain`` (navigation terrains only)."""
    try:
        return PLANNING_CASES[terrain]
    except KeyError as err:
        raise ParameterError(f"terrain {terrain!r} has no planning case; known: "
                             f"{', '.join(PLANNING_CASES)}") from err


@dataclass(eq=False)
class TerrainPlans:
    """One terrain's plans: results and scores keyed by (mapper, policy), for tables/figures.

    ``occupied`` keeps each map's occupied cells (centres, sizes) for plotting; the
    maps themselves (Octomap: millions of free leaves) are not kept.
    """

    terrain: str
    case: PlanningCase
    surface: TrueSurface | None
    occupied: dict[str, tuple[NDArray[np.float64], NDArray[np.float64]]] = field(
        default_factory=dict)
    results: dict[tuple[str, str], PlanResult] = field(default_factory=dict)
    scores: dict[tuple[str, str], PathScore] = field(default_factory=dict)


def plan_maps(terrain: str, maps: Mapping[str, PlanningMap], case: PlanningCase,
              surface: TrueSurface | None = None,
              policies: Sequence[str] = POLICIES) -> TerrainPlans:
    """Plan on every map with every policy; score found paths when ``surface`` is given."""
    out = TerrainPlans(terrain, case, surface)
    for name, pmap in maps.items():
        occ = pmap.occupied
        out.occupied[name] = (pmap.cells.centers[occ], pmap.cells.sizes[occ])
        for policy in policies:
            res = plan_path(pmap, case.start, case.goal, bounds=case.box, step=case.step,
                            clearance=case.clearance, unknown=policy)
            out.results[name, policy] = res
            if surface is not None:
                out.scores[name, policy] = score_path(res.path, surface, case.clearance)
    return out


def planning_rows(plans: TerrainPlans) -> list[JSONDict]:
    """One table row per (mapper, policy) of ``plans``."""
    rows: list[JSONDict] = []
    for (name, policy), res in plans.results.items():
        score = plans.scores.get((name, policy))
        rows.append({
            "terrain": plans.terrain, "mapper": name, "unknown": policy, "status": res.status,
            "path_found": res.found, "length_m": res.length_m, "straight_m": res.straight_m,
            "detour_ratio": res.length_m / res.straight_m, "build_s": res.build_s,
            "search_s": res.search_s, "nodes": res.nodes, "unknown_nodes": res.unknown_nodes,
            "free_nodes": res.free_nodes, "clearance_m": plans.case.clearance,
            "step_m": plans.case.step,
            **({} if score is None else {k: v for k, v in score.as_dict().items()
                                         if k != "samples"}),
        })
    return rows


def _terrain_maps(data: Registered, name: str, mappers: Iterable[str],
                  params: Mapping[str, Mapping[str, object]] | None) -> dict[str, PlanningMap]:
    chosen: dict[str, Mapping[str, object]] = {**mapper_params(name), **(params or {})}
    return {m: planning_map(run(data, MapSettings(m, chosen.get(m, {}))).mapper) for m in mappers}


def planning_experiment(terrains: Sequence[str], data_dir: str | os.PathLike[str] = "data",
                        frames: int | None = None, seed: int = 0, *,
                        mappers: Sequence[str] = ("octomap", "alte3d"),
                        params: Mapping[str, Mapping[str, object]] | None = None,
                        policies: Sequence[str] = POLICIES,
                        progress: bool = True) -> tuple[pd.DataFrame, list[TerrainPlans]]:
    """Simulate (if needed), map and plan every terrain; the table and per-terrain plans.

    ``params`` overrides chapter 4 mapper parameters by mapper name.
    """
    for name in terrains:
        planning_case(name)
    bad = [p for p in policies if p not in POLICIES]
    if bad or not policies:
        raise ParameterError(f"unknown policies {bad or list(policies)}; valid: {POLICIES}")
    plans = []
    for name in progress_bar(terrains, desc="planning", unit="terrain", disable=not progress):
        data = terrain(name, data_dir, seed, frames)
        maps = _terrain_maps(data, name, mappers, params)
        truth = ground_truth(data)
        plans.append(plan_maps(name, maps, planning_case(name), None if truth is None
                               else truth.surface, policies))
    table = pd.DataFrame([row for p in plans for row in planning_rows(p)])
    return table, plans


def write_planning_table(table: pd.DataFrame, out_dir: str | os.PathLike[str],
                         overwrite: bool = False) -> Path:
    """Write ``out_dir/table_planning.csv`` (atomic; refuses to overwrite by default)."""
    return write_csv(table, out_dir, "table_planning", overwrite)
