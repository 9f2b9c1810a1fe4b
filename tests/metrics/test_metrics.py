"""Tests for alte.metrics: Hausdorff distances and the ground-truth metrics."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from scipy.spatial.distance import cdist

from alte.errors import MetricsError
from alte.mappers.base import Cells
from alte.metrics import (
    TrueSurface,
    cell_at_xy,
    directed_distances,
    distance_to_boxes,
    free_space_truth,
    ground_truth_metrics,
    hausdorff,
    height_metrics_2d,
)
from alte.metrics.hausdorff import target_index

coords = st.floats(-10, 10, allow_nan=False, width=64)
point_sets = st.integers(1, 25).flatmap(lambda n: arrays(np.float64, (n, 3), elements=coords))


def _brute(a: np.ndarray, b: np.ndarray) -> tuple[float, float]:
    d = cdist(a, b)
    hd = max(d.min(axis=1).max(), d.min(axis=0).max())
    mhd = max(d.min(axis=1).mean(), d.min(axis=0).mean())
    return hd, mhd


@settings(max_examples=60, deadline=None)
@given(point_sets, point_sets)
def test_hausdorff_matches_brute_force(a, b):
    res = hausdorff(a, b)
    hd, mhd = _brute(a, b)
    assert res.hd == pytest.approx(hd, abs=1e-9)
    assert res.mhd == pytest.approx(mhd, abs=1e-9)
    assert res.hd >= res.mhd >= 0
    swapped = hausdorff(b, a)
    assert swapped.hd == pytest.approx(res.hd) and swapped.mhd == pytest.approx(res.mhd)
    assert swapped.h_ab == pytest.approx(res.h_ba) and swapped.mh_ab == pytest.approx(res.mh_ba)


def test_distances_equal_open3d_and_scipy_to_the_last_bit():
    """The KD-tree's nearest distances are open3d's (the benchmark peer) and scipy's."""
    import open3d as o3d
    from scipy.spatial import cKDTree

    rng = np.random.default_rng(7)
    a = rng.normal(0, 20, (20_000, 3))
    b = np.round(rng.normal(0, 20, (6_000, 3)) / 0.2) * 0.2  # lattice corners, like a map's
    for src, dst in ((a, b), (b, a)):
        ours = directed_distances(src, dst)
        cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(src))
        peer = np.asarray(cloud.compute_point_cloud_distance(
            o3d.geometry.PointCloud(o3d.utility.Vector3dVector(dst))))
        assert np.array_equal(ours, peer)
        assert np.array_equal(ours, cKDTree(dst).query(src, k=1)[0])
    res = hausdorff(a, b)
    assert res.h_ab == directed_distances(a, b).max()
    assert res.mh_ba == directed_distances(b, a).mean()


def test_hausdorff_zero_on_identical_sets():
    a = np.random.default_rng(1).random((200, 3))
    res = hausdorff(a, a.copy())
    assert res.hd == 0.0 and res.mhd == 0.0
    assert set(res.as_dict()) == {"hd", "mhd", "h_ab", "h_ba", "mh_ab", "mh_ba"}


def test_hausdorff_outlier_moves_hd_more_than_mhd():
    a = np.random.default_rng(2).random((500, 3))
    b = np.vstack([a, [[50.0, 0.0, 0.0]]])
    res = hausdorff(a, b)
    assert res.hd > 40 and res.mhd < 0.2


@pytest.mark.parametrize(
    ("a", "b", "match"),
    [
        (np.zeros((0, 3)), np.zeros((2, 3)), "set A is empty"),
        (np.zeros((2, 3)), np.zeros((0, 3)), "set B is empty"),
        (np.zeros((2, 2)), np.zeros((2, 3)), r"set A must have shape \(N, 3\)"),
        (np.zeros((2, 3)), np.full((2, 3), np.nan), "set B contains NaN"),
    ],
)
def test_hausdorff_rejects_bad_sets(a, b, match):
    with pytest.raises(MetricsError, match=match):
        hausdorff(a, b)


@pytest.mark.parametrize(
    ("source", "target", "match"),
    [
        (np.zeros((0, 3)), np.zeros((2, 3)), "set source is empty"),
        (np.zeros((2, 3)), np.zeros((0, 3)), "set target is empty"),
        (np.zeros(3), np.zeros((2, 3)), r"set source must have shape \(N, 3\)"),
        (np.zeros((2, 3)), np.array([[0.0, np.inf, 0.0]]), "set target contains NaN or inf"),
    ],
)
def test_directed_distances_rejects_bad_sets(source, target, match):
    with pytest.raises(MetricsError, match=match):
        directed_distances(source, target)
    with pytest.raises(MetricsError, match=match):  # the same checks with a prepared target
        directed_distances(source, target_index(target))


def test_a_prepared_target_gives_the_same_distances():
    rng = np.random.default_rng(2)
    target = rng.normal(0, 10, (5000, 3))
    index = target_index(target)
    for source in (rng.normal(0, 10, (3000, 3)), rng.normal(0, 80, (300, 3)), target[:7]):
        assert np.array_equal(directed_distances(source, index),
                              directed_distances(source, target))


def test_distance_to_boxes_matches_brute_force():
    rng = np.random.default_rng(3)
    centers = rng.uniform(0, 5, (40, 3))
    sizes = rng.choice([0.25, 0.5, 1.0], size=(40, 1)) * np.ones((1, 3))
    points = rng.uniform(-1, 6, (300, 3))
    got = distance_to_boxes(points, centers, sizes, max_distance=0.7)
    gap = np.maximum(np.abs(points[:, None] - centers[None]) - sizes[None] / 2, 0)
    want = np.linalg.norm(gap, axis=2).min(axis=1)
    want[want > 0.7] = np.inf
    np.testing.assert_allclose(got, want)


def test_cell_at_xy_finds_containing_rectangle():
    centers = np.array([[0.5, 0.5, 1.0], [1.5, 0.5, 2.0], [1.0, 2.0, 0.0]])
    sizes = np.array([[1.0, 1.0, 0.0], [1.0, 1.0, 0.0], [2.0, 2.0, 0.0]])
    xy = np.array([[0.2, 0.9], [1.9, 0.1], [0.1, 2.5], [5.0, 5.0]])
    np.testing.assert_array_equal(cell_at_xy(xy, centers, sizes), [0, 1, 2, -1])


def test_cell_at_xy_matches_brute_force_on_a_quadtree():
    """Leaves of a real 2D map (many sizes, edges shared) against a brute-force search."""
    from alte.mappers import make_mapper

    rng = np.random.default_rng(3)
    pts = np.column_stack([rng.uniform(0, 32, 4000) ** 1.2 / 2, rng.uniform(0, 32, 4000),
                           rng.normal(0, 1, 4000)])
    tree = make_mapper("quadtree", {"max_points": 20})
    tree.build(pts)
    cells = tree.cells()
    xy = np.vstack([rng.uniform(-2, 40, (3000, 2)),  # inside and outside the root
                    cells.centers[:200, :2] + cells.sizes[:200, :2] / 2])  # on corners
    lo = cells.centers[:, :2] - cells.sizes[:, :2] / 2
    hi = cells.centers[:, :2] + cells.sizes[:, :2] / 2
    inside = np.all((xy[:, None] >= lo[None] - 1e-9) & (xy[:, None] <= hi[None] + 1e-9), axis=2)
    got = cell_at_xy(xy, cells.centers, cells.sizes)
    assert np.array_equal(got >= 0, inside.any(axis=1))
    assert inside[np.flatnonzero(got >= 0), got[got >= 0]].all()
    # one cell alone: its four corners and edge midpoints are in it
    box = np.array([[1.0, 1.0, 0.0]]), np.array([[2.0, 2.0, 0.0]])
    rim = np.array([[0, 0], [2, 0], [0, 2], [2, 2], [1, 0], [2, 1], [1, 2], [0, 1]], float)
    assert (cell_at_xy(rim, *box) == 0).all()
    assert (cell_at_xy(rim + np.array([2.001, 0.0]), *box) == -1).all()


def _scene() -> TrueSurface:
    """A 10 x 10 m ground plane (id 0) and a closed 2 x 2 x 2 m box on it (id 1)."""
    ground_v = np.array([[0, 0, 0], [10, 0, 0], [10, 10, 0], [0, 10, 0]], float)
    ground_t = np.array([[0, 1, 2], [0, 2, 3]])
    lo, hi = np.array([4.0, 4.0, 0.0]), np.array([6.0, 6.0, 2.0])
    corners = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], float)
    box_v = lo + corners * (hi - lo)
    faces = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1),
             (2, 3, 7), (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)]
    box_t = np.array(faces) + 4
    return TrueSurface(np.vstack([ground_v, box_v]), np.vstack([ground_t, box_t]),
                       np.array([0, 0] + [1] * 12), {0: "ground", 1: "box"})


def _voxel_cells(points: np.ndarray, step: float) -> Cells:
    keys = np.unique(np.floor(points / step).astype(np.int64), axis=0)
    centers = (keys + 0.5) * step
    n = len(centers)
    return Cells(centers, np.full((n, 3), step), np.ones(n), np.ones(n, bool), np.zeros(n, int))


def test_true_surface_queries():
    surf = _scene()
    pts = np.array([[5.0, 5.0, 3.0], [1.0, 1.0, 1.0], [5.0, 5.0, 1.0], [1.0, 1.0, -0.5]])
    np.testing.assert_allclose(surf.distance(pts), [1.0, 1.0, 1.0, 0.5], atol=1e-5)
    np.testing.assert_array_equal(surf.inside(pts), [False, False, True, True])
    np.testing.assert_allclose(surf.top_height(np.array([[5.0, 5.0], [1.0, 1.0], [20, 20]])),
                               [2.0, 0.0, np.nan], atol=1e-5)
    one, two = surf.sample(500, seed=4), surf.sample(500, seed=4)
    np.testing.assert_array_equal(one.points, two.points)
    assert np.all(surf.distance(one.points) < 1e-4)
    # areas: ground 100 m^2, box 20 m^2 of sides+top+bottom 24 -> about 24 / 124 on the box
    assert 0.1 < np.mean(one.object_ids == 1) < 0.3


@pytest.mark.parametrize(
    ("args", "match"),
    [
        ((np.zeros((0, 3)), np.zeros((1, 3), int)), "vertices must be"),
        ((np.zeros((3, 3)), np.zeros((1, 2), int)), "triangles must be"),
        ((np.zeros((3, 3)), np.array([[0, 1, 5]])), "out of range"),
        ((np.eye(3), np.array([[0, 1, 2]]), np.array([0, 1])), "2 object ids for 1 triangles"),
    ],
)
def test_true_surface_rejects_bad_meshes(args, match):
    with pytest.raises(MetricsError, match=match):
        TrueSurface(*args)


def test_true_surface_rejects_bad_sample_count():
    with pytest.raises(MetricsError, match="sample count"):
        _scene().sample(0)


def test_completeness_drops_when_part_of_the_map_is_removed():
    surf = _scene()
    dense = surf.sample(60_000, seed=5).points
    cells = _voxel_cells(dense, 0.25)
    full = ground_truth_metrics(cells, surf, dims=3, cloud=dense, tolerance=0.1,
                                n_samples=20_000)
    assert full["completeness"] > 0.99 and full["completeness_seen"] > 0.99
    assert full["accuracy_mean_m"] < 0.13 and full["phantom_share"] == 0.0
    keep = ~((cells.centers[:, 0] > 3.5) & (cells.centers[:, 0] < 6.5)
             & (cells.centers[:, 1] > 3.5) & (cells.centers[:, 1] < 6.5))
    part = Cells(cells.centers[keep], cells.sizes[keep], cells.value[keep],
                 cells.occupied[keep], cells.level[keep])
    less = ground_truth_metrics(part, surf, dims=3, cloud=dense, tolerance=0.1,
                                n_samples=20_000)
    assert less["completeness"] < full["completeness"] - 0.1
    assert less["completeness_by_object"]["box"] < 0.05
    assert less["completeness_by_object"]["ground"] > 0.9
    assert np.isnan(less["free_truly_free_share"])


def test_completeness_seen_ignores_unscanned_surfaces():
    surf = _scene()
    dense = surf.sample(60_000, seed=6).points
    ground_only = dense[dense[:, 2] < 1e-6]
    cells = _voxel_cells(ground_only, 0.25)
    res = ground_truth_metrics(cells, surf, dims=3, cloud=ground_only, tolerance=0.1,
                               n_samples=20_000)
    assert res["completeness"] < 0.9 and res["completeness_seen"] > 0.99


def test_phantom_cells_are_counted():
    surf = _scene()
    cells = _voxel_cells(np.array([[1.0, 1.0, 0.0], [1.0, 1.0, 5.0]]), 0.25)
    res = ground_truth_metrics(cells, surf, dims=3, cloud=np.zeros((0, 3)), tolerance=0.1,
                               n_samples=1000)
    assert res["phantom_share"] == 0.5
    assert np.isnan(res["completeness_seen"]) and res["seen_share"] == 0.0


def test_free_space_truth_by_volume():
    surf = _scene()
    centers = np.array([[5.0, 5.0, 1.0], [1.0, 1.0, 1.0], [8.0, 8.0, 4.0]])
    sizes = np.array([[1.0] * 3, [1.0] * 3, [2.0] * 3])
    cells = Cells(centers, sizes, np.full(3, 0.2), np.zeros(3, bool), np.zeros(3, int))
    assert free_space_truth(cells, surf) == pytest.approx(9.0 / 10.0)


def _height_cells(step: float, height_of_box: float = 2.0) -> Cells:
    g = np.arange(step / 2, 10, step)
    xy = np.stack(np.meshgrid(g, g), -1).reshape(-1, 2)
    on_box = np.all((xy > 4) & (xy < 6), axis=1)
    z = np.where(on_box, height_of_box, 0.0)
    n = len(xy)
    sizes = np.column_stack([np.full((n, 2), step), np.zeros(n)])
    return Cells(np.column_stack([xy, z]), sizes, z, on_box, np.zeros(n, int))


def test_height_metrics_2d_perfect_and_degraded_maps():
    surf = _scene()
    bounds = np.array([[0, 0, -1], [10, 10, 5]], float)
    perfect = height_metrics_2d(_height_cells(0.5), surf, bounds, 0.2, 0.1)
    assert perfect["height_rmse_m"] < 1e-5
    assert perfect["unknown_share"] == 0.0 and perfect["completeness"] == 1.0
    flat = height_metrics_2d(_height_cells(0.5, height_of_box=0.0), surf, bounds, 0.2, 0.1)
    assert flat["height_rmse_m"] == pytest.approx(2.0 * np.sqrt(0.04), rel=0.05)
    assert flat["completeness"] == pytest.approx(0.96, abs=0.01)
    cells = _height_cells(0.5)
    half = cells.centers[:, 0] < 5
    cut = Cells(cells.centers[half], cells.sizes[half], cells.value[half],
                cells.occupied[half], cells.level[half])
    res = ground_truth_metrics(cut, surf, dims=2, cloud=np.zeros((0, 3)), bounds=bounds,
                               tolerance=0.1)
    assert res["unknown_share"] == pytest.approx(0.5) and res["completeness"] == pytest.approx(0.5)
    assert res["accuracy_mean_m"] < 1e-5


def test_height_metrics_2d_rejects_empty_grid():
    with pytest.raises(MetricsError, match="grid_step=20"):
        height_metrics_2d(_height_cells(0.5), _scene(), np.array([[0, 0, 0], [10, 10, 5]]),
                          20.0, 0.1)


@pytest.mark.parametrize(("kwargs", "match"), [({"dims": 4}, "dims must be 2 or 3"),
                                               ({"dims": 3, "tolerance": 0.0}, "tolerance")])
def test_ground_truth_metrics_rejects_bad_arguments(kwargs, match):
    with pytest.raises(MetricsError, match=match):
        ground_truth_metrics(_height_cells(1.0), _scene(), cloud=np.zeros((0, 3)), **kwargs)


def test_inside_is_right_where_closed_objects_overlap():
    base = _scene()
    shift = np.array([1.0, 0.0, 0.0])
    box = base.vertices[4:]
    verts = np.vstack([base.vertices, box + shift])
    tris = np.vstack([base.triangles, base.triangles[2:] + 8])
    surf = TrueSurface(verts, tris, np.array([0, 0] + [1] * 12 + [2] * 12))
    pts = np.array([[5.5, 5.0, 1.0], [6.5, 5.0, 1.0], [7.5, 5.0, 1.0], [3.0, 5.0, 1.0]])
    np.testing.assert_array_equal(surf.inside(pts), [True, True, False, False])


def test_free_space_truth_estimate_from_a_volume_weighted_sample():
    surf = _scene()
    rng = np.random.default_rng(7)
    centers = np.column_stack([rng.uniform(0, 10, (5000, 2)), rng.uniform(0.05, 3, 5000)])
    sizes = rng.choice([0.1, 0.2], size=(5000, 1)) * np.ones((1, 3))
    cells = Cells(centers, sizes, np.full(5000, 0.2), np.zeros(5000, bool), np.zeros(5000, int))
    exact = free_space_truth(cells, surf)
    assert 0.9 < exact < 1.0  # the box holds 8 of the 300 m^3 sampled
    assert free_space_truth(cells, surf, max_cells=2000) == pytest.approx(exact, abs=0.03)


def test_free_space_draws_are_numpy_choice_draws_sorted():
    from alte.metrics.freespace import _draw

    rng = np.random.default_rng(3)
    volume, free = rng.random(50_000) ** 3, np.arange(7, 50_007)
    want = np.random.default_rng(11).choice(free, size=4000, p=volume / volume.sum())
    np.testing.assert_array_equal(_draw(free, volume, 4000, 11), np.sort(want))
