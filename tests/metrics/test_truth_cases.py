"""Truth metrics at their edges: no cells, one point, the phantom boundary, boxes of two sizes.

Every expected value is worked out by hand in the comments.
"""

from __future__ import annotations

import numpy as np
import pytest

from alte.metrics.surface import SurfaceSamples
from alte.metrics.truth import accuracy_of, distance_to_boxes, seen_mask


def test_accuracy_of_no_cells_is_undefined_under_its_three_names() -> None:
    found = accuracy_of(np.empty(0), np.empty((0, 3)), 0.1)
    assert list(found) == ["accuracy_mean_m", "accuracy_p95_m", "phantom_share"]
    assert all(np.isnan(v) for v in found.values())


def test_a_phantom_is_a_cell_whose_centre_lies_beyond_its_half_diagonal_plus_tolerance() -> None:
    sizes = np.array([[1.0, 0, 0], [2.0, 0, 0], [1.0, 0, 0], [4.0, 0, 0]])  # half 0.5 1 0.5 2
    dist = np.array([0.75, 1.5, 0.5, 2.5])  # beyond the half diagonal by .25 .5 0 .5
    found = accuracy_of(dist, sizes, tolerance=0.25)
    assert found["phantom_share"] == 0.5  # .5 and .5 exceed .25; exactly .25 does not
    assert found["accuracy_mean_m"] == pytest.approx(1.3125)
    # sorted .5 .75 1.5 2.5: the 95th percentile lies 0.85 of the way from 1.5 to 2.5
    assert found["accuracy_p95_m"] == pytest.approx(2.35)


def _samples(points: list[list[float]]) -> SurfaceSamples:
    return SurfaceSamples(np.array(points, dtype=float), np.zeros(len(points), dtype=int))


def test_nothing_is_seen_without_a_cloud_and_a_lone_point_sees_its_neighbourhood() -> None:
    samples = _samples([[0, 0, 0], [1, 0, 0], [5, 0, 0]])
    none = seen_mask(samples, np.empty((0, 3)), 0.5)
    assert none.dtype == bool and none.tolist() == [False, False, False]
    one = seen_mask(samples, np.array([[0.8, 0.0, 0.0]]), 0.5)
    assert one.tolist() == [False, True, False]  # 0.8 and 0.2 from the point


def test_distance_to_a_box_for_one_point_and_boxes_of_two_sizes() -> None:
    centers = np.array([[0.0, 0, 0], [10.0, 0, 0]])
    sizes = np.array([[1.0, 1, 1], [4.0, 4, 4]])
    assert distance_to_boxes(np.array([[0.2, 0, 0]]), centers, sizes, 1.0).tolist() == [0.0]
    # near the large box only (2.5 from its face at x = 8): the small box's group finds
    # no pair, the large one's must still be read
    found = distance_to_boxes(np.array([[5.5, 0, 0]]), centers, sizes, 3.0)
    assert found.tolist() == pytest.approx([2.5])
    assert distance_to_boxes(np.array([[5.5, 0, 0]]), centers, sizes, 2.0).tolist() == [np.inf]
