"""Path planning over 3D maps: lattice classification, clearance, search, policies, scores."""

from __future__ import annotations

import numpy as np
import pytest

from alte.errors import MapperError, MetricsError, ParameterError
from alte.lab.studies import planning
from alte.mappers import make_mapper
from alte.mappers.base import Cells
from alte.metrics import TrueSurface

BOUNDS = np.array([[0.0, 0.0, 0.0], [10.0, 10.0, 4.0]])
START, GOAL = (2.0, 3.0, 2.0), (8.0, 3.0, 2.0)


def _grid_cells(occupied_boxes: list[tuple[tuple[float, ...], tuple[float, ...]]],
                unknown_boxes: tuple = (), edge: float = 0.5) -> Cells:
    """Cubes of ``edge`` tiling BOUNDS; occupied inside ``occupied_boxes``, dropped (unknown)
    inside ``unknown_boxes``: an Octomap-like map with explicit free cells."""
    axes = [np.arange(lo + edge / 2, hi, edge) for lo, hi in zip(*BOUNDS, strict=True)]
    centers = np.stack([g.reshape(-1) for g in np.meshgrid(*axes, indexing="ij")], axis=1)

    def inside(boxes: tuple | list) -> np.ndarray:
        hit = np.zeros(len(centers), bool)
        for lo, hi in boxes:
            hit |= ((centers > lo) & (centers < hi)).all(axis=1)
        return hit

    keep = ~inside(unknown_boxes)
    occ = inside(occupied_boxes)[keep]
    centers = centers[keep]
    n = len(centers)
    return Cells(centers, np.full((n, 3), edge), occ.astype(float), occ, np.full(n, 5))


def _box_distance(points: np.ndarray, lo: tuple, hi: tuple) -> np.ndarray:
    gap = np.maximum(np.maximum(np.asarray(lo) - points, points - np.asarray(hi)), 0.0)
    return np.linalg.norm(gap, axis=1)


def _plan(cells: Cells, observes_free: bool = True, **kw: object) -> planning.PlanResult:
    pmap = planning.PlanningMap.from_cells(cells, observes_free, "synthetic")
    args = {"bounds": BOUNDS, "step": 0.5, "clearance": 0.5, "unknown": "free"} | kw
    return planning.plan_path(pmap, START, GOAL, **args)


WALL = ((5.0, 0.0, 0.0), (5.5, 7.0, 4.0))


def test_open_space_path_is_straight() -> None:
    res = _plan(_grid_cells([]))
    assert res.found and res.status == "found"
    assert res.length_m == pytest.approx(6.0)
    assert res.straight_m == pytest.approx(6.0)
    np.testing.assert_allclose(res.path[[0, -1]], [START, GOAL])


def test_wall_between_start_and_goal_is_bypassed_with_clearance() -> None:
    res = _plan(_grid_cells([WALL]), clearance=0.6)
    assert res.found
    assert res.length_m > res.straight_m + 2.0  # must go round the wall's end at y = 7
    samples, _ = planning.densify(res.path, 0.02)
    assert _box_distance(samples, *WALL).min() >= 0.6
    assert res.path[:, 1].max() > 7.0 + 0.6


def test_clearance_is_respected_even_between_lattice_nodes() -> None:
    pillar = ((4.9, 2.9, 0.0), (5.1, 3.1, 4.0))
    for clearance in (0.0, 0.3, 1.0):
        res = _plan(_pillar_map(pillar),
                    clearance=clearance, step=0.4)
        assert res.found
        samples, _ = planning.densify(res.path, 0.01)
        assert _box_distance(samples, *pillar).min() > clearance


def _pillar_map(pillar: tuple) -> Cells:
    lo, hi = np.asarray(pillar[0]), np.asarray(pillar[1])
    center = (lo + hi) / 2
    return Cells(center[None], (hi - lo)[None], np.ones(1), np.ones(1, bool), np.zeros(1, int))


def test_closed_wall_gives_no_path_and_says_so() -> None:
    closed = ((5.0, 0.0, 0.0), (5.5, 10.0, 4.0))
    res = _plan(_grid_cells([closed]))
    assert res.status == "no_path" and not res.found
    assert np.isnan(res.length_m) and res.path.shape == (0, 3)


def test_unknown_policy_decides_whether_unknown_space_is_crossed() -> None:
    hole = ((4.0, 0.0, 0.0), (6.0, 6.0, 4.0))  # unknown block on the straight line
    cells = _grid_cells([], unknown_boxes=[hole])
    optimistic = _plan(cells, unknown="free")
    conservative = _plan(cells, unknown="occupied", clearance=0.3)
    assert optimistic.length_m == pytest.approx(6.0)
    assert conservative.found and conservative.length_m > 8.0
    samples, _ = planning.densify(conservative.path, 0.02)
    assert _box_distance(samples, *hole).min() > 0.3


def test_map_without_free_space_blocks_everything_when_unknown_is_occupied() -> None:
    cells = _grid_cells([WALL])
    res = _plan(cells, observes_free=False, unknown="occupied")
    assert res.status == "start_blocked" and res.free_nodes == 0
    assert res.unknown_nodes == res.nodes - int(np.count_nonzero(
        planning.classify(planning.Lattice.over(BOUNDS, 0.5).points(),
                          planning.PlanningMap.from_cells(cells, False)) == planning.OCCUPIED))
    assert _plan(cells, observes_free=False, unknown="free").found


def test_goal_inside_obstacle_is_reported() -> None:
    block = ((7.0, 2.0, 0.0), (9.0, 4.0, 4.0))
    assert _plan(_grid_cells([block])).status == "goal_blocked"


def test_locate_handles_variable_cell_sizes() -> None:
    centers = np.array([[1.0, 1.0, 1.0], [2.5, 0.5, 0.5], [3.0, 3.0, 3.0]])
    sizes = np.array([[2.0] * 3, [1.0] * 3, [2.0] * 3])
    cells = Cells(centers, sizes, np.zeros(3), np.array([True, False, False]),
                  np.array([1, 2, 1]))
    pts = np.array([[0.1, 1.9, 0.5], [2.9, 0.1, 0.9], [2.5, 2.5, 2.5], [2.5, 1.5, 0.5],
                    [-0.1, 0.0, 0.0]])
    np.testing.assert_array_equal(planning.locate(cells, pts), [0, 1, 2, -1, -1])
    states = planning.classify(pts, planning.PlanningMap.from_cells(cells, True))
    expect = [planning.OCCUPIED, planning.FREE, planning.FREE, planning.UNKNOWN, planning.UNKNOWN]
    np.testing.assert_array_equal(states, expect)


def test_near_boxes_is_exact_at_corners() -> None:
    centers, sizes = np.array([[0.0, 0.0, 0.0]]), np.array([[2.0, 2.0, 2.0]])
    d = 0.5 / np.sqrt(3)  # corner (1,1,1) offset by 0.5 along the diagonal
    pts = np.array([[1 + d, 1 + d, 1 + d], [1.49, 0.0, 0.0], [1.51, 0.0, 0.0]])
    hit = planning.near_boxes(pts, centers, sizes, np.zeros(1, int), 0.5 + 1e-9)
    np.testing.assert_array_equal(hit, [True, True, False])


def test_lattice_graph_connects_26_neighbours() -> None:
    graph = planning.lattice_graph(np.ones((2, 2, 2), bool), 2.0)
    assert graph.nnz == 28  # every pair of the 8 corners of a cube
    weights = np.sort(graph.data)
    assert weights[0] == pytest.approx(2.0) and weights[-1] == pytest.approx(2.0 * np.sqrt(3))
    blocked = np.ones((3, 1, 1), bool)
    blocked[1] = False
    assert planning.lattice_graph(blocked, 1.0).nnz == 0
    assert len(planning.OFFSETS) == 13


def test_score_path_counts_collisions_with_the_true_mesh() -> None:
    surface = _cube_surface(((4.0, -1.0, -1.0), (6.0, 1.0, 1.0)))
    through = np.array([[0.0, 0.0, 0.0], [10.0, 0.0, 0.0]])
    score = planning.score_path(through, surface, clearance=0.5, spacing=0.01)
    assert score.inside_samples > 0 and score.min_clearance_m == 0.0
    assert score.colliding_length_m == pytest.approx(3.0, abs=0.05)  # 2 m inside + 2 x 0.5
    above = np.array([[0.0, 0.0, 2.0], [10.0, 0.0, 2.0]])
    clear = planning.score_path(above, surface, clearance=0.5, spacing=0.01)
    assert clear.colliding_samples == 0 and clear.min_clearance_m == pytest.approx(1.0, abs=1e-3)
    empty = planning.score_path(np.empty((0, 3)), surface, 0.5)
    assert empty.samples == 0 and np.isnan(empty.min_clearance_m)


def _cube_surface(box: tuple) -> TrueSurface:
    lo, hi = np.asarray(box[0]), np.asarray(box[1])
    corners = np.array([[i >> 2 & 1, i >> 1 & 1, i & 1] for i in range(8)], float)
    verts = lo + corners * (hi - lo)
    faces = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1),
             (2, 3, 7), (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)]
    return TrueSurface(verts, np.array(faces))


def test_densify_keeps_ends_and_length() -> None:
    path = np.array([[0.0, 0, 0], [1.0, 0, 0], [1.0, 2.0, 0]])
    samples, weights = planning.densify(path, 0.3)
    np.testing.assert_allclose(samples[[0, -1]], path[[0, -1]])
    assert weights.sum() == pytest.approx(3.0)
    assert np.linalg.norm(np.diff(samples, axis=0), axis=1).max() <= 0.3 + 1e-12


def test_planning_map_of_real_mappers() -> None:
    rng = np.random.default_rng(0)
    pts = np.column_stack([rng.uniform(0, 4, 2000), rng.uniform(0, 4, 2000), np.zeros(2000)])
    octo = make_mapper("octomap", resolution=2.0)
    octo.insert(pts, np.array([2.0, 2.0, 3.0]))
    pmap = planning.planning_map(octo)
    assert pmap.free.any() and pmap.occupied.any() and not (pmap.free & pmap.occupied).any()
    alte = make_mapper("alte3d", max_res=3, min_pts=2, min_pts_split=4, occupancy_level=0)
    alte.build(pts)
    amap = planning.planning_map(alte)
    assert amap.occupied.any() and not amap.free.any()
    quad = make_mapper("quadtree")
    quad.build(pts)
    with pytest.raises(MapperError, match="quadtree: path planning needs a 3D map"):
        planning.planning_map(quad)


@pytest.mark.parametrize(("kw", "match"), [
    ({"step": 0.0}, "planning step=0.0"),
    ({"step": 0.001}, "lattice nodes .* use a larger step"),
    ({"clearance": -1.0}, "planning clearance=-1.0"),
    ({"unknown": "maybe"}, "planning unknown='maybe'"),
    ({"bounds": [[0, 0, 0], [0, 1, 1]]}, "planning bounds"),
])
def test_plan_path_rejects_bad_parameters(kw: dict, match: str) -> None:
    with pytest.raises(ParameterError, match=match):
        _plan(_grid_cells([]), **kw)


def test_start_and_goal_outside_the_domain_are_rejected() -> None:
    pmap = planning.PlanningMap.from_cells(_grid_cells([]), True)
    with pytest.raises(ParameterError, match=r"planning start .* outside the lattice"):
        planning.plan_path(pmap, (-5, 0, 0), GOAL, bounds=BOUNDS, step=0.5, clearance=0.1)
    with pytest.raises(ParameterError, match="planning goal must be 3 finite numbers"):
        planning.plan_path(pmap, START, (1, np.nan, 1), bounds=BOUNDS, step=0.5, clearance=0.1)


def test_bad_inputs_raise_named_errors() -> None:
    flat = Cells(np.zeros((1, 3)), np.array([[1.0, 1.0, 0.0]]), np.zeros(1), np.ones(1, bool),
                 np.zeros(1, int))
    with pytest.raises(MapperError, match="flat: 1 cells have no 3D extent"):
        planning.PlanningMap.from_cells(flat, True, "flat")
    mixed = Cells(np.zeros((2, 3)), np.array([[1.0] * 3, [2.0] * 3]), np.zeros(2),
                  np.ones(2, bool), np.zeros(2, int))
    with pytest.raises(MapperError, match="cells of level 0 differ in size"):
        planning.locate(mixed, np.zeros((1, 3)), "mixed")
    with pytest.raises(MetricsError, match="spacing=0"):
        planning.densify(np.zeros((2, 3)), 0)
    with pytest.raises(MetricsError, match="path must be"):
        planning.densify(np.zeros((1, 3)), 0.1)
    with pytest.raises(ParameterError, match="terrain 'sim_lan_1' has no planning case"):
        planning.planning_case("sim_lan_1")
    with pytest.raises(ParameterError, match="unknown policies"):
        planning.planning_experiment(["exp_nav_1"], policies=["bold"])


def test_tiny_simulated_terrain(tmp_path) -> None:
    table, plans = planning.planning_experiment(["exp_nav_1"], tmp_path, frames=10,
                                                progress=False)
    assert len(table) == 4 and set(table["mapper"]) == {"octomap", "alte3d"}
    assert set(table["unknown"]) == set(planning.POLICIES)
    alte_cons = table[(table.mapper == "alte3d") & (table.unknown == "occupied")].iloc[0]
    assert not alte_cons.path_found and alte_cons.status == "start_blocked"
    found = table[table.path_found]
    assert len(found) >= 2
    assert (found.length_m >= found.straight_m - 1e-9).all()
    assert (found.build_s > 0).all() and (found.search_s > 0).all()
    assert np.isfinite(found.min_clearance_m).all()
    assert plans[0].terrain == "exp_nav_1" and plans[0].occupied["octomap"][0].shape[1] == 3


def test_write_planning_table_refuses_to_overwrite(tmp_path) -> None:
    import pandas as pd

    from alte.errors import AlteError

    table = pd.DataFrame([{"terrain": "t", "length_m": 1.5}])
    path = planning.write_planning_table(table, tmp_path)
    assert path.name == "table_planning.csv" and pd.read_csv(path).length_m[0] == 1.5
    with pytest.raises(AlteError, match=r"table_planning\.csv already exists"):
        planning.write_planning_table(table, tmp_path)
    planning.write_planning_table(table, tmp_path, overwrite=True)


def test_plan_maps_scores_and_plots_synthetic_terrain() -> None:
    import matplotlib

    matplotlib.use("Agg")
    from alte.lab.studies.planning.figures import plot_plans

    case = planning.PlanningCase(START, GOAL, tuple(BOUNDS.reshape(-1)), 0.5, 0.5)
    unseen = ((4.5, 0.0, 0.0), (5.5, 5.0, 4.0))  # a real block the map did not see
    maps = {"seen": planning.PlanningMap.from_cells(_grid_cells([unseen]), True, "seen"),
            "blind": planning.PlanningMap.from_cells(_grid_cells([]), True, "blind")}
    plans = planning.plan_maps("synthetic", maps, case, _cube_surface(unseen))
    rows = {(r["mapper"], r["unknown"]): r for r in planning.planning_rows(plans)}
    assert rows["seen", "free"]["colliding_length_m"] == 0.0
    assert rows["blind", "free"]["inside_samples"] > 0
    assert rows["blind", "free"]["colliding_length_m"] == pytest.approx(2.0, abs=0.2)
    fig = plot_plans([plans]).figure
    assert len([ax for ax in fig.axes if ax.get_visible()]) == 2
    assert "seen" in fig.axes[0].get_title()
