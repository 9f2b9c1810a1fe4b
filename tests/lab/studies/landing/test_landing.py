"""Landing-zone detection: synthetic rasters, ground truth, scores, errors."""

from __future__ import annotations

import dataclasses

import matplotlib

matplotlib.use("Agg")

import numpy as np
import pandas as pd
import pytest
from matplotlib.collections import EllipseCollection
from support.example import NoisyGrid

from alte.errors import AlteError, MetricsError, ParameterError
from alte.lab.studies.landing import (
    SITE_COLUMNS,
    Centres,
    Detection,
    LandingSettings,
    RasterGeometry,
    detect_sites,
    evaluate_landing,
    feasible_centres,
    landing_param_sets,
    landing_params,
    landing_summary,
    landing_table,
    landing_truth,
    load_terrains,
    object_footprints,
    plane_features,
    rasterise,
    rasterise_sigma,
    score_detection,
    score_landing,
    truth_centres,
    write_landing_table,
)
from alte.lab.studies.landing.figures import plot_landing_runs
from alte.mappers.base import Cells
from alte.metrics import TrueSurface
from alte.pipeline import InputKind
from alte.sim import SceneBuilder

PARAMS = LandingSettings(radius=1.0, margin=0.5, clearance=1.0, step=0.25, max_sites=3)


def _flat(size: float = 20.0, step: float = 0.25) -> tuple[RasterGeometry, np.ndarray]:
    grid = RasterGeometry.from_bounds(np.array([[0.0, 0.0], [size, size]]), step)
    return grid, np.zeros(grid.shape)


def _box_edge_distance(xy: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """Distance from points to the square [lo, hi]^2 in x/y."""
    gap = np.maximum(np.maximum(lo - xy, xy - hi), 0.0)
    return np.linalg.norm(gap, axis=1)


# -- parameters ---------------------------------------------------------------------------
@pytest.mark.parametrize(("field", "value", "match"), [
    ("radius", 0.0, r"landing: radius=0.0 out of range \(radius > 0\)"),
    ("margin", -0.1, "margin=-0.1"),
    ("max_slope_deg", 90.0, "max_slope_deg"),
    ("max_roughness", float("nan"), "max_roughness=nan must be finite"),
    ("step", 2.0, r"step=2.0 out of range \(0 < step <= radius\)"),
    ("max_sites", 1.5, "max_sites=1.5 must be an integer"),
    ("clearance", "wide", "clearance='wide' is not a valid float"),
])
def test_landing_params_are_validated(field, value, match):
    with pytest.raises(ParameterError, match=match):
        LandingSettings(**{field: value})


def test_presets_per_terrain_and_overrides():
    sim, lab = landing_params("sim_lan_1"), landing_params("exp_lan_2", clearance=0.3)
    assert sim.radius == 1.0 and sim.keep_out == 2.0 and sim.disk == 1.5
    assert lab.radius < sim.radius and lab.clearance == 0.3 and lab.step < sim.step
    with pytest.raises(ParameterError,
                       match=r"landing: unknown parameter\(s\) wingspan; valid: clearance"):
        landing_params("sim_lan_1", wingspan=2.0)


# -- raster -------------------------------------------------------------------------------
def test_rasterise_takes_the_height_of_the_cell_holding_each_pixel():
    cells = Cells(np.array([[1.0, 1.0, 0.5], [3.0, 1.0, np.nan], [2.0, 3.0, 2.0]]),
                  np.array([[2.0, 2.0, 0.0], [2.0, 2.0, 0.0], [4.0, 2.0, 0.0]]),
                  np.zeros(3), np.zeros(3, bool), np.zeros(3, np.int64))
    grid = RasterGeometry.from_bounds(np.array([[0.0, 0.0, -1.0], [5.0, 4.0, 1.0]]), 0.5)
    height = rasterise(cells, grid)
    assert height.shape == (8, 10)
    assert np.all(height[:4, :4] == 0.5) and np.all(height[4:, :8] == 2.0)
    assert np.isnan(height[:4, 4:8]).all() and np.isnan(height[:, 8:]).all()


def test_grid_rejects_bad_bounds_and_steps():
    with pytest.raises(ParameterError, match="step=0"):
        RasterGeometry.from_bounds(np.array([[0.0, 0.0], [1.0, 1.0]]), 0)
    with pytest.raises(ParameterError, match=r"smaller than one 2\.0 m pixel"):
        RasterGeometry.from_bounds(np.array([[0.0, 0.0], [1.0, 1.0]]), 2.0)
    with pytest.raises(ParameterError, match=r"must be \(2, 2\) or \(2, 3\)"):
        RasterGeometry.from_bounds(np.zeros(4), 0.1)


def test_plane_features_measure_slope_and_roughness():
    grid, _ = _flat(10.0)
    xs, ys = grid.axes()
    gx, _gy = np.meshgrid(xs, ys)
    tilted = np.tan(np.radians(20.0)) * gx + 3.0
    feats = plane_features(tilted, grid.step, 1.5)
    assert np.allclose(feats.slope_deg, 20.0, atol=1e-6)
    assert np.nanmax(feats.roughness) < 1e-6
    noisy = np.random.default_rng(0).normal(0.0, 0.05, grid.shape)
    rough = plane_features(noisy, grid.step, 1.5).roughness[10:-10, 10:-10]
    assert 0.04 < np.median(rough) < 0.06
    holed = tilted.copy()
    holed[:, :] = np.nan
    assert np.isnan(plane_features(holed, grid.step, 1.5).slope_deg).all()


# -- detection on synthetic maps ----------------------------------------------------------
def test_sites_avoid_a_box_by_the_clearance():
    grid, height = _flat()
    xs, ys = grid.axes()
    gx, gy = np.meshgrid(xs, ys)
    inbox = (np.abs(gx - 10.0) <= 2.0) & (np.abs(gy - 10.0) <= 2.0)
    height[inbox] = 2.0
    det = detect_sites(height, grid, PARAMS)  # ground plane fitted by MSAC
    assert det.centres.obstacle[inbox].all() and not det.centres.obstacle[~inbox].any()
    feasible_xy = np.column_stack([gx[det.centres.feasible], gy[det.centres.feasible]])
    gap = _box_edge_distance(feasible_xy, 8.0, 12.0)
    assert len(gap) and gap.min() >= PARAMS.keep_out - grid.step
    gap_all = _box_edge_distance(np.column_stack([gx.ravel(), gy.ravel()]), 8.0, 12.0)
    open_ground = (gap_all.reshape(grid.shape) > 3.0) & (det.centres.known_dist > 2.0)
    assert det.centres.feasible[open_ground].all()
    chosen = det.chosen[["x", "y"]].to_numpy()
    assert len(chosen) == 1 and _box_edge_distance(chosen, 8.0, 12.0)[0] >= PARAMS.keep_out
    assert list(det.sites.columns) == list(SITE_COLUMNS)


def test_an_unknown_hole_is_never_a_site():
    grid, height = _flat()
    xs, ys = grid.axes()
    gx, gy = np.meshgrid(xs, ys)
    hole = np.hypot(gx - 10.0, gy - 10.0) < 3.0
    height[hole] = np.nan
    det = detect_sites(height, grid, PARAMS, ground=0.0)
    assert not det.centres.feasible[hole].any()
    dist = np.hypot(gx - 10.0, gy - 10.0)[det.centres.feasible]
    assert dist.min() > 3.0 + PARAMS.disk - grid.step
    # near the raster's edge the disk is outside the map: unknown, so not feasible either
    assert not det.centres.feasible[:, :5].any() and det.centres.feasible.any()
    all_unknown = detect_sites(np.full(grid.shape, np.nan), grid, PARAMS)
    assert len(all_unknown.sites) == 0 and not all_unknown.centres.feasible.any()


@pytest.mark.parametrize(("slope", "accepted"), [(5.0, True), (20.0, False)])
def test_a_slope_above_the_threshold_is_rejected(slope, accepted):
    grid, _ = _flat()
    xs, _ys = grid.axes()
    height = np.tile(np.tan(np.radians(slope)) * xs, (grid.shape[0], 1))
    # a ground height of the slope's middle: obstacles are judged against it, so give a
    # generous step and test the slope alone
    params = LandingSettings(obstacle_height=50.0, max_slope_deg=10.0)
    det = detect_sites(height, grid, params, ground=float(np.median(height)))
    assert bool(det.centres.feasible.any()) is accepted
    assert (len(det.sites) > 0) is accepted


def test_rough_ground_is_rejected_and_sites_are_ranked():
    grid, height = _flat()
    rng = np.random.default_rng(1)
    height[:, :40] = rng.normal(0.0, 0.2, (grid.shape[0], 40))  # x < 10 m: rubble
    height[:, 44:48] = 1.0  # a wall between the rubble and the smooth part
    det = detect_sites(height, grid, LandingSettings(obstacle_height=0.8, max_sites=1),
                       ground=0.0)
    xs, _ = grid.axes()
    assert not det.centres.feasible[:, xs < 10.0].any()
    assert det.centres.feasible[:, xs > 15.0].any()
    assert det.sites["chosen"].sum() == 1 and (np.diff(det.sites["score"]) <= 0).all()


def test_two_sites_are_ranked_by_score():
    grid, height = _flat(20.0)
    height[:, 36:40] = 2.0  # wall at x = 9-10 m: a narrow site left, a wide one right
    height[:, :16] = np.nan
    det = detect_sites(height, grid, PARAMS, ground=0.0)
    assert len(det.sites) == 2 and det.sites["rank"].tolist() == [1, 2]
    assert det.sites["x"].iloc[0] > 10.0 and det.sites["area_m2"].iloc[0] > \
        det.sites["area_m2"].iloc[1]


def test_detection_errors():
    grid, height = _flat()
    with pytest.raises(ParameterError, match=r"height raster \(3, 3\) does not match"):
        detect_sites(np.zeros((3, 3)), grid, PARAMS)
    with pytest.raises(ParameterError, match=r"grid step 0\.25 m differs from the parameter"):
        detect_sites(height, grid, LandingSettings(step=0.5))
    with pytest.raises(ParameterError, match="must be 2D arrays of one shape"):
        feasible_centres(height, np.zeros((2, 2), bool), 0.25, PARAMS)


# -- ground truth and scores --------------------------------------------------------------
def _rail_surface(classes: bool = True) -> TrueSurface:
    b = SceneBuilder()
    b.ground("ground", (-1.0, -1.0, 21.0, 21.0))
    b.slab("rail", "fence", (10.1, 10.01), (16.0, 0.05), z=(0.5, 0.6))  # thinner than a pixel
    scene = b.build()
    return TrueSurface(scene.vertices, scene.triangles, scene.object_ids, scene.labels,
                       scene.classes if classes else None)


def test_truth_sees_objects_thinner_than_a_pixel():
    surface = _rail_surface()
    grid, _ = _flat()
    rail = object_footprints(surface, grid, np.array([1]))
    rows, cols = np.nonzero(rail)
    assert set(rows) == {39, 40} and cols.min() == 8 and cols.max() == 72
    truth = truth_centres(surface, grid, PARAMS, z_start=5.0)
    xs, ys = grid.axes()
    gx, gy = np.meshgrid(xs, ys)
    near = (np.abs(gy - 10.0) < 1.5) & (np.abs(gx - 10.0) < 7.0)
    assert not truth.feasible[near].any() and truth.feasible.any()
    with pytest.raises(MetricsError, match="no object classes"):
        truth_centres(_rail_surface(classes=False), grid, PARAMS, z_start=5.0)


def _centres(feasible: np.ndarray) -> Centres:
    inf = np.full(feasible.shape, np.inf)
    return Centres(feasible, inf, inf, np.zeros(feasible.shape), np.zeros(feasible.shape),
                   np.zeros(feasible.shape, bool))


def test_scores_count_chosen_sites_and_areas():
    grid = RasterGeometry((0.0, 0.0), 1.0, (4, 4))
    params = LandingSettings(radius=1.0, step=1.0, max_sites=2)
    detected = np.zeros((4, 4), bool)
    detected[0, :] = True
    true = np.zeros((4, 4), bool)
    true[0, :2] = True
    true[3, :] = True
    sites = pd.DataFrame({"rank": [1, 2, 3], "x": [0.5, 3.5, 2.5], "y": [0.5, 0.5, 3.5],
                          "chosen": [True, True, False]})
    det = Detection(grid, np.zeros((4, 4)), _centres(detected), sites)
    scores = score_detection(det, _centres(true), params)
    assert scores["precision"] == 0.5 and scores["best_site_safe"]
    assert scores["area_precision"] == 0.5 and scores["recall"] == pytest.approx(2 / 6)
    assert scores["chosen"] == 2 and scores["sites"] == 3
    with pytest.raises(MetricsError, match="rasters differ"):
        score_detection(det, _centres(np.zeros((2, 2), bool)), params)


@pytest.fixture(scope="module")
def tiny_lan(tmp_path_factory):
    (data,) = load_terrains(["sim_lan_1"], tmp_path_factory.mktemp("landing"), frames=10,
                            progress=False)
    return data


@pytest.fixture(scope="module")
def tiny_table(tiny_lan):
    return landing_table([tiny_lan], {"sim_lan_1": landing_params("sim_lan_1", step=0.5)},
                         progress=False)


def test_ground_truth_scoring_on_a_tiny_simulated_terrain(tiny_lan):
    params = landing_params("sim_lan_1", step=0.5)
    truth = landing_truth(tiny_lan, params)
    assert 0.5 < truth.feasible.mean() < 0.95  # open ground minus the 4 objects and edges
    scores = score_landing(tiny_lan, "alte2d", {"kappa": 0.1, "max_res": 6, "min_pts": 10},
                           params)
    assert scores["chosen"] >= 1 and scores["precision"] == 1.0
    assert 0.9 < scores["area_precision"] <= 1.0 and 0.0 < scores["recall"] <= 1.0
    assert scores["recall_known"] >= scores["recall"]
    with pytest.raises(ParameterError, match="'octomap' is not a 2D mapper"):
        evaluate_landing(tiny_lan, "octomap", {}, params)


def test_without_ground_truth_only_detection_is_reported(tiny_lan):
    params = landing_params("sim_lan_1", step=0.5)
    real = dataclasses.replace(tiny_lan, source=dataclasses.replace(tiny_lan.source,
                                                               kind=InputKind.BAG))
    run = evaluate_landing(real, "quadtree", {"max_points": 200}, params)
    assert run.truth is None and set(run.scores) == {"sites", "chosen"}
    assert run.scores["sites"] >= 1
    with pytest.raises(MetricsError, match="has no ground truth"):
        landing_truth(real, params)


def test_landing_table_rows_summary_and_csv(tiny_table, tmp_path):
    table, runs = tiny_table
    sets = landing_param_sets("sim_lan_1")
    assert [s[1] for s in sets] == ["quadtree", "alte2d", "quadtree", "quadtree", "alte2d",
                                    "alte2d"]
    assert len(table) == len(sets) == len(runs)
    assert set(table["terrain"]) == {"sim_lan_1"} and table["precision"].between(0, 1).all()
    summary = landing_summary(table)
    assert summary[["terrain", "mapper"]].values.tolist() == [["sim_lan_1", "quadtree"],
                                                              ["sim_lan_1", "alte2d"]]
    assert summary["recall"].iloc[0] == pytest.approx(
        table.loc[table["mapper"] == "quadtree", "recall"].mean())
    with pytest.raises(ParameterError, match="lacks columns precision"):
        landing_summary(table.drop(columns="precision"))
    path = write_landing_table(table, tmp_path)
    assert path.name == "table_landing.csv" and len(pd.read_csv(path)) == len(sets)
    with pytest.raises(AlteError, match=r"table_landing\.csv already exists"):
        write_landing_table(table, tmp_path)
    with pytest.raises(ParameterError, match="no chapter 4 parameters"):
        landing_param_sets("nowhere")


def test_sites_are_drawn_one_panel_per_run(tiny_table):
    _, runs = tiny_table
    fig = plot_landing_runs(runs, only="ch4").figure
    titles = [ax.get_title() for ax in fig.axes if ax.get_visible() and ax.get_title()]
    assert len(titles) == 2 and titles[0].startswith("sim_lan_1 quadtree (ch4 quadtree)")
    rings = [c for ax in fig.axes for c in ax.collections if isinstance(c, EllipseCollection)]
    assert sum(len(c.get_offsets()) for c in rings) == sum(len(r.detection.chosen)
                                                           for r in runs[:2])
    with pytest.raises(ParameterError, match="no runs to draw"):
        plot_landing_runs(runs, only="nothing")


def test_rasterise_sigma_and_its_refusal():
    cells = Cells(np.array([[1.0, 1.0, 0.0], [3.0, 1.0, 2.0]]), np.array([[2.0, 2.0, 0.0]] * 2),
                  np.zeros(2), np.ones(2, bool), np.zeros(2, np.int64),
                  {"variance": np.array([0.04, 0.01])})
    grid = RasterGeometry.from_bounds(np.array([[0.0, 0.0], [4.0, 2.0]]), 1.0)
    assert rasterise_sigma(cells, grid).tolist() == [[0.2, 0.2, 0.1, 0.1]] * 2
    with pytest.raises(ParameterError, match="carry no height variance"):
        rasterise_sigma(dataclasses.replace(cells, layers={}), grid)


def test_a_height_sigma_bound_makes_unsure_pixels_unknown(tiny_lan):
    """The example grid with a (5 cm)^2 / count variance: a bound under the sigma of every
    cell leaves no site; one over all of them changes nothing; a map without variance is
    refused; further mappers' settings rows join the parameter sets."""
    params = landing_params("sim_lan_1", step=0.5)
    free = evaluate_landing(tiny_lan, NoisyGrid, {"cell": 1.0}, params)
    loose = evaluate_landing(tiny_lan, NoisyGrid, {"cell": 1.0},
                             params.replace(max_height_sigma=0.06))
    tight = evaluate_landing(tiny_lan, NoisyGrid, {"cell": 1.0},
                             params.replace(max_height_sigma=0.001))
    assert free.scores["chosen"] >= 1 and loose.scores == free.scores
    assert tight.scores["sites"] == 0 and tight.detection.height.size > 0
    with pytest.raises(ParameterError, match=r"max_height_sigma=0\.1 needs a map whose cells "
                                             r"carry a height variance; 'quadtree' has none"):
        evaluate_landing(tiny_lan, "quadtree", {}, params.replace(max_height_sigma=0.1))
    sets = landing_param_sets("sim_lan_1", extra=(NoisyGrid,))
    assert [(label, p) for label, m, p in sets if m is NoisyGrid] == [
        (f"grid row {i}", {"cell": c}) for i, c in enumerate((0.25, 0.5, 1.0, 2.0))]
    with pytest.raises(ParameterError, match=r"max_height_sigma=0\.0 out of range"):
        params.replace(max_height_sigma=0.0)
