"""Ground-truth metrics on scenes small enough to compute every expected value by hand."""

from __future__ import annotations

import numpy as np
import pytest

from alte.errors import MetricsError
from alte.mappers.base import Cells
from alte.metrics import TrueSurface, ground_truth_metrics, height_metrics_2d
from alte.metrics.surface import SurfaceSamples
from alte.metrics.truth import (
    accuracy,
    completeness,
    completeness_by_class,
    completeness_by_object,
    distance_to_boxes,
    seen_mask,
)


def _scene(classes: dict[int, str] | None = None) -> TrueSurface:
    """A 10 x 10 m ground plane (id 0) and a closed 2 x 2 x 2 m box on it (id 1, 4..6 m)."""
    ground_v = np.array([[0, 0, 0], [10, 0, 0], [10, 10, 0], [0, 10, 0]], float)
    lo, hi = np.array([4.0, 4.0, 0.0]), np.array([6.0, 6.0, 2.0])
    corners = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], float)
    faces = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1),
             (2, 3, 7), (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)]
    return TrueSurface(np.vstack([ground_v, lo + corners * (hi - lo)]),
                       np.vstack([[[0, 1, 2], [0, 2, 3]], np.array(faces) + 4]),
                       np.array([0, 0] + [1] * 12), {0: "ground", 1: "box"}, classes)


def _cells(centers: list[list[float]], sizes: list[list[float]],
           occupied: list[bool] | None = None) -> Cells:
    c, s = np.array(centers, float), np.array(sizes, float)
    occ = np.ones(len(c), bool) if occupied is None else np.array(occupied)
    return Cells(c, s, c[:, 2].copy(), occ, np.zeros(len(c), int))


def test_per_object_and_per_class_shares_counted_by_hand() -> None:
    samples = SurfaceSamples(np.zeros((10, 3)), np.array([0, 0, 0, 0, 1, 1, 2, 2, 2, 3]))
    covered = np.array([1, 1, 0, 0, 1, 0, 1, 1, 1, 0], bool)
    by_object = completeness_by_object(samples, covered, {0: "ground", 2: "tree_a"})
    assert by_object == {"ground": 0.5, "object_1": 0.5, "tree_a": 1.0, "object_3": 0.0}
    # object 0 has no class: left out; trees 1 and 2 pooled by sample: (1 + 3) / 5
    by_class = completeness_by_class(samples, covered, {1: "tree", 2: "tree", 3: "overhang"})
    assert by_class == {"overhang": 0.0, "tree": 0.8}


def test_distance_to_boxes_by_hand() -> None:
    centers = [[0.0, 0.0, 0.0], [10.0, 0.0, 0.0]]
    sizes = [[2.0, 2.0, 2.0], [4.0, 2.0, 2.0]]   # two size groups
    points = np.array([[0.5, 0.0, 0.0],            # inside the first box
                       [3.0, 0.0, 0.0],            # 2 m off its +x face
                       [2.0, 2.0, 0.0],            # 1 m off an edge on x and y
                       [13.0, 0.0, 0.0],           # 1 m off the second box's +x face
                       [5.0, 0.0, 5.0]])           # 3 m from the first box, 4 m above
    got = distance_to_boxes(points, np.array(centers), np.array(sizes), 2.5)
    np.testing.assert_allclose(got, [0.0, 2.0, np.sqrt(2.0), 1.0, np.inf])
    assert np.isinf(distance_to_boxes(points, np.array(centers), np.array(sizes), 1.9)[1])
    assert np.isinf(distance_to_boxes(points, np.zeros((0, 3)), np.zeros((0, 3)), 9.0)).all()
    covered = completeness(SurfaceSamples(points, np.zeros(5, int)), np.array(centers),
                           np.array(sizes), 1.0)
    np.testing.assert_array_equal(covered, [True, False, False, True, False])


def test_accuracy_and_phantoms_by_hand() -> None:
    surf = _scene()
    centers = np.array([[1.0, 1.0, 0.05], [1.0, 1.0, 1.0]])   # 0.05 m and 1 m above ground
    sizes = np.array([[0.1] * 3, [0.2] * 3])
    got = accuracy(centers, sizes, surf, tolerance=0.2)
    assert got["accuracy_mean_m"] == pytest.approx(0.525, abs=1e-5)
    assert got["accuracy_p95_m"] == pytest.approx(0.05 + 0.95 * 0.95, abs=1e-5)
    # the far cell: 1 m minus its half diagonal (0.173 m) is beyond 0.2 m; the near one is not
    assert got["phantom_share"] == 0.5
    big = accuracy(centers, np.array([[0.1] * 3, [1.8] * 3]), surf, tolerance=0.2)
    assert big["phantom_share"] == 0.0   # 1 - 1.559 < 0.2: it may touch the ground
    assert all(np.isnan(v) for v in accuracy(np.zeros((0, 3)), np.zeros((0, 3)), surf,
                                             0.2).values())


def test_height_metrics_on_a_unit_grid_by_hand() -> None:
    """Grid points at x, y = 0.5 .. 9.5 (100); the box top (z = 2) holds 4 of them."""
    surf = _scene()
    bounds = np.array([[0.0, 0.0, -1.0], [10.0, 10.0, 5.0]])
    flat = height_metrics_2d(_cells([[5.0, 5.0, 0.0]], [[10.0, 10.0, 0.0]]), surf, bounds,
                             1.0, 0.1)
    assert flat["height_rmse_m"] == pytest.approx(np.sqrt(4 * 2.0**2 / 100), abs=1e-5)
    assert flat["unknown_share"] == 0.0 and flat["completeness"] == pytest.approx(0.96)
    # the west half mapped flat (2 box points in it), the east half a cell of unknown height
    half = _cells([[2.5, 5.0, 0.0], [7.5, 5.0, np.nan]], [[5.0, 10.0, 0.0], [5.0, 10.0, 0.0]])
    got = height_metrics_2d(half, surf, bounds, 1.0, 0.1)
    assert got["unknown_share"] == 0.5
    assert got["height_rmse_m"] == pytest.approx(np.sqrt(2 * 2.0**2 / 50), abs=1e-5)
    assert got["completeness"] == pytest.approx(48 / 100)
    # a map 0.15 m off everywhere: within a 0.2 m tolerance, not within 0.1 m
    high = _cells([[5.0, 5.0, 0.15]], [[10.0, 10.0, 0.0]])
    off = bounds * [[1, 1, 1], [1, 1, 1]]
    off[0, :2], off[1, :2] = [0.0, 0.0], [4.0, 10.0]     # only the ground: x 0.5 .. 3.5
    assert height_metrics_2d(high, surf, off, 1.0, 0.2)["completeness"] == 1.0
    assert height_metrics_2d(high, surf, off, 1.0, 0.1)["completeness"] == 0.0
    assert height_metrics_2d(high, surf, off, 1.0, 0.1)["height_rmse_m"] == pytest.approx(
        0.15, abs=1e-5)


def test_seen_mask_and_the_3d_metrics_by_hand() -> None:
    samples = SurfaceSamples(np.array([[0.0, 0, 0], [1.0, 0, 0], [5.0, 0, 0]]), np.zeros(3, int))
    cloud = np.array([[0.05, 0.0, 0.0], [1.3, 0.0, 0.0]])
    np.testing.assert_array_equal(seen_mask(samples, cloud, 0.1), [True, False, False])
    np.testing.assert_array_equal(seen_mask(samples, cloud, 0.31), [True, True, False])
    assert not seen_mask(samples, np.zeros((0, 3)), 1.0).any()
    surf = _scene({1: "block"})
    # one occupied cell over the ground's west 3 m (0.1 m thick), one free cell: the box
    # (x 4 .. 6) is not mapped
    cells = _cells([[1.5, 5.0, 0.0], [5.0, 5.0, 1.0]], [[3.0, 10.0, 0.2], [1.0, 1.0, 1.0]],
                   occupied=[True, False])
    grid = np.arange(0.0, 10.001, 0.05)
    cloud_west = np.array([[x, y, 0.0] for x in grid[grid <= 3.0] for y in grid])
    got = ground_truth_metrics(cells, surf, dims=3, cloud=cloud_west, tolerance=0.1,
                               n_samples=20_000, seed=3)
    # areas: ground 100 m^2, box 24 m^2; covered: the ground to x = 3 + 0.1
    assert got["completeness"] == pytest.approx(31 / 124, abs=0.01)
    assert got["completeness_by_object"]["ground"] == pytest.approx(0.31, abs=0.015)
    assert got["completeness_by_object"]["box"] == 0.0
    assert got["completeness_by_class"] == {"block": 0.0}
    assert got["seen_share"] == pytest.approx(30.5 / 124, abs=0.01)
    assert got["completeness_seen"] == pytest.approx(1.0, abs=0.01)
    assert got["free_truly_free_share"] == 0.0    # the free cell is inside the box
    assert got["accuracy_mean_m"] == pytest.approx(0.0, abs=1e-5)
    assert "completeness_by_class" not in ground_truth_metrics(
        cells, _scene(), dims=3, cloud=cloud_west, tolerance=0.1, n_samples=1000)


def test_the_height_grid_starts_half_a_step_inside_the_bounds() -> None:
    """Grid points at x = 0.25, 0.75, .. 5.75 and y = 2.25, .. 4.75 (step 0.5 inside
    x 0-6, y 2-5); a map over x < a, y < b knows the points below both cuts."""
    surf = _scene()
    bounds = np.array([[0.0, 2.0, -1.0], [6.0, 5.0, 3.0]])

    def unknown(a: float, b: float) -> float:
        cells = _cells([[a / 2, b / 2, 0.0]], [[a, b, 0.0]])
        return height_metrics_2d(cells, surf, bounds, 0.5, 0.1)["unknown_share"]

    assert unknown(4.6, 3.6) == pytest.approx(1 - (9 / 12) * (3 / 6))   # x to 4.25, y to 3.25
    assert unknown(4.2, 3.2) == pytest.approx(1 - (8 / 12) * (2 / 6))   # x to 3.75, y to 2.75
    one = height_metrics_2d(_cells([[0.5, 0.5, 0.0]], [[1.0, 1.0, 0.0]]), surf,
                            np.array([[0.0, 0.0, -1.0], [1.0, 1.0, 3.0]]), 1.0, 0.1)
    assert one == {"height_rmse_m": pytest.approx(0.0, abs=1e-6), "unknown_share": 0.0,
                   "completeness": 1.0}                                # a single point
    with pytest.raises(MetricsError, match="leaves no grid"):           # no row of points
        height_metrics_2d(_cells([[0.5, 0.5, 0.0]], [[1.0, 1.0, 0.0]]), surf,
                          np.array([[0.0, 0.0, -1.0], [10.0, 0.1, 3.0]]), 0.2, 0.1)
