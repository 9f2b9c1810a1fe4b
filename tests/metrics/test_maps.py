"""alte.metrics.maps: one map's metrics, and the definitions of set B."""

from __future__ import annotations

import numpy as np
import pytest

from alte.errors import MetricsError
from alte.mappers import make_mapper
from alte.metrics.maps import SET_B, measure_map, set_b_points


def _steps() -> np.ndarray:
    """16 x 16 m of flat ground with a 2 m high 4 x 4 m block."""
    rng = np.random.default_rng(0)
    xy = rng.uniform(0, 16, size=(20_000, 2))
    z = np.where((xy[:, 0] > 6) & (xy[:, 0] < 10) & (xy[:, 1] > 6) & (xy[:, 1] < 10), 2.0, 0.0)
    return np.column_stack([xy, z + rng.normal(0, 0.01, len(z))])


@pytest.fixture(scope="module")
def maps():
    cloud = _steps()
    quadtree = make_mapper("quadtree", {"max_points": 200})
    quadtree.build(cloud)
    alte3d = make_mapper("alte3d", {"max_res": 5, "min_pts": 3, "occupancy_level": 0})
    alte3d.build(cloud)
    return cloud, quadtree, alte3d


def test_set_b_definitions_of_a_2d_map(maps):
    cloud, quadtree, _ = maps
    cells = quadtree.cells()
    corners = set_b_points(quadtree, cells, "corners")
    np.testing.assert_array_equal(corners, quadtree.corners())
    centers = set_b_points(quadtree, cells, "centers")
    assert len(centers) == np.isfinite(cells.centers[:, 2]).sum() < len(corners)
    occupied = set_b_points(quadtree, cells, "occupied")
    # only the block is above Quadtree's 0.5 m height threshold
    assert 0 < len(occupied) < len(corners) and np.allclose(occupied[:, 2], 2.0, atol=0.05)
    values = {rule: measure_map(quadtree, cloud, elapsed_s=1.0, set_b=rule) for rule in SET_B}
    # the ground is far from set B of the occupied leaves only: MHD cloud -> map grows
    assert values["occupied"].mh_ab_m > 10 * values["corners"].mh_ab_m
    # a centre lies nearer the points it summarises than its corners do
    assert values["centers"].mh_ba_m < values["corners"].mh_ba_m
    assert values["corners"].basis_functions == values["occupied"].basis_functions


def test_set_b_of_a_3d_map_is_its_occupied_cells(maps):
    cloud, _, alte3d = maps
    cells = alte3d.cells()
    np.testing.assert_array_equal(set_b_points(alte3d, cells, "occupied"), alte3d.corners())
    centers = set_b_points(alte3d, cells, "centers")
    assert len(centers) == cells.occupied.sum()
    assert measure_map(alte3d, cloud, elapsed_s=0.0, set_b="centers").mh_ba_m < measure_map(
        alte3d, cloud, elapsed_s=0.0).mh_ba_m


def test_unknown_set_b_is_an_error(maps):
    cloud, quadtree, _ = maps
    with pytest.raises(MetricsError, match="set B 'edges': expected one of corners, centers"):
        measure_map(quadtree, cloud, elapsed_s=0.0, set_b="edges")
    with pytest.raises(MetricsError, match="set B 'edges'"):
        set_b_points(quadtree, quadtree.cells(), "edges")
