"""Tests for alte.ground.clustering: Euclidean clusters and the obstacle map."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from alte.errors import ParameterError
from alte.ground import PlaneFit
from alte.ground.clustering import OBSTACLE_COLUMNS, euclidean_clusters, obstacle_map


def box_grid(lo, hi, step=0.1):
    """Points on a regular grid filling the box [lo, hi] (a solid obstacle)."""
    axes = [np.arange(a, b + step / 2, step) for a, b in zip(lo, hi, strict=True)]
    return np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)


BOXES = [
    box_grid((0, 0, 0), (1.0, 1.0, 2.0)),  # 11 x 11 x 21 = 2541 points
    box_grid((5, 0, 0), (5.5, 0.5, 1.0)),  # 6 x 6 x 11 = 396
    box_grid((0, 5, 0), (0.3, 5.3, 0.5)),  # 4 x 4 x 6 = 96
]


def shuffled_boxes(seed=0):
    pts = np.vstack(BOXES)
    truth = np.repeat(np.arange(3), [len(b) for b in BOXES])
    perm = np.random.default_rng(seed).permutation(len(pts))
    return pts[perm], truth[perm]


def test_three_boxes_three_clusters_ordered_by_size():
    pts, truth = shuffled_boxes()
    labels = euclidean_clusters(pts, tolerance=0.15)
    np.testing.assert_array_equal(labels, truth)
    np.testing.assert_array_equal(np.bincount(labels), [2541, 396, 96])


def test_tolerance_below_spacing_splits_everything():
    pts = BOXES[2]
    labels = euclidean_clusters(pts, tolerance=0.05)
    assert len(np.unique(labels)) == len(pts)


def test_chain_links_far_ends():
    pts = np.c_[np.arange(0, 10, 0.5), np.zeros(20), np.zeros(20)]
    assert (euclidean_clusters(pts, 0.5) == 0).all()  # pairs at exactly tolerance link
    assert len(np.unique(euclidean_clusters(pts, 0.49))) == 20


def test_size_filter_rejects_small_and_large():
    pts, truth = shuffled_boxes(1)
    labels = euclidean_clusters(pts, 0.15, min_size=100, max_size=1000)
    np.testing.assert_array_equal(labels, np.where(truth == 1, 0, -1))
    labels = euclidean_clusters(pts, 0.15, min_size=100)
    np.testing.assert_array_equal(labels, np.where(truth == 2, -1, truth))


def test_equal_sizes_ordered_by_first_point_and_empty_input():
    pts = np.array([[10.0, 0, 0], [0, 0, 0], [10.1, 0, 0], [0.1, 0, 0]])
    np.testing.assert_array_equal(euclidean_clusters(pts, 0.2), [0, 1, 0, 1])
    assert euclidean_clusters(np.empty((0, 3)), 1.0).shape == (0,)


@pytest.mark.parametrize(("kwargs", "match"), [
    ({"tolerance": 0.0}, "tolerance"),
    ({"tolerance": np.nan}, "tolerance"),
    ({"tolerance": 1.0, "min_size": 0}, "min_size"),
    ({"tolerance": 1.0, "min_size": 5, "max_size": 4}, "max_size"),
])
def test_cluster_parameter_errors(kwargs, match):
    with pytest.raises(ParameterError, match=match):
        euclidean_clusters(np.zeros((3, 3)), **kwargs)


@pytest.mark.parametrize(("points", "match"), [
    (np.zeros((3, 2)), "shape"),
    (np.array([[np.inf, 0, 0]]), "NaN or inf"),
])
def test_cluster_point_errors(points, match):
    with pytest.raises(ParameterError, match=match):
        euclidean_clusters(points, 1.0)
    with pytest.raises(ParameterError, match=match):
        obstacle_map(points, np.zeros(len(points), int))


def test_obstacle_map_on_known_boxes():
    pts, _ = shuffled_boxes(2)
    table = obstacle_map(pts, euclidean_clusters(pts, 0.15))
    assert tuple(table.columns) == OBSTACLE_COLUMNS
    np.testing.assert_array_equal(table["label"], [0, 1, 2])
    np.testing.assert_array_equal(table["n_points"], [2541, 396, 96])
    np.testing.assert_allclose(table[["x", "y", "z"]], [[0.5, 0.5, 1.0], [5.25, 0.25, 0.5],
                                                       [0.15, 5.15, 0.25]], atol=1e-12)
    # farthest horizontal point of a grid box is a corner: half the diagonal
    np.testing.assert_allclose(table["radius"], np.hypot([0.5, 0.25, 0.15], [0.5, 0.25, 0.15]))
    np.testing.assert_allclose(table[["xmin", "ymin", "zmin"]].iloc[1], [5, 0, 0], atol=1e-12)
    np.testing.assert_allclose(table[["xmax", "ymax", "zmax"]].iloc[2], [0.3, 5.3, 0.5])
    np.testing.assert_allclose(table["height"], [2.0, 1.0, 0.5], atol=1e-12)


def test_obstacle_map_height_from_ground_and_rejected_points():
    pts = np.array([[0, 0, 1.0], [0.2, 0, 3.0], [9, 9, 9]])
    labels = np.array([0, 0, -1])
    plane = PlaneFit(np.array([0, 0, 1.0]), 0.5, np.zeros(3, bool), 0.0)  # z = -0.5
    table = obstacle_map(pts, labels, ground=plane)
    assert len(table) == 1
    assert table["height"].iloc[0] == pytest.approx(3.5)
    assert table["radius"].iloc[0] == pytest.approx(0.1)
    assert obstacle_map(pts, labels, ground=0.25)["height"].iloc[0] == pytest.approx(2.75)
    empty = obstacle_map(pts, np.full(3, -1))
    assert isinstance(empty, pd.DataFrame)
    assert empty.empty
    assert tuple(empty.columns) == OBSTACLE_COLUMNS


def test_obstacle_map_label_and_ground_errors():
    pts = np.zeros((3, 3))
    with pytest.raises(ParameterError, match="labels must be 3 integers"):
        obstacle_map(pts, np.zeros(2, int))
    with pytest.raises(ParameterError, match="labels must be 3 integers"):
        obstacle_map(pts, np.zeros(3))
    with pytest.raises(ParameterError, match="ground"):
        obstacle_map(pts, np.zeros(3, int), ground=np.nan)
