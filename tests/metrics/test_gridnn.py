"""Tests for alte.metrics._gridnn: the grid search gives a KD-tree's distances bit for bit."""

from __future__ import annotations

import numba
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from pykdtree.kdtree import KDTree
from scipy.spatial import cKDTree

from alte.metrics import nearest
from alte.metrics._gridnn import (
    MAX_LOAD,
    RINGS,
    bounds,
    build_grid,
    first_side,
    query_grid,
)
from alte.metrics.nearest import nearest_distances


def _reference(queries: np.ndarray, targets: np.ndarray) -> np.ndarray:
    ours = cKDTree(targets).query(queries, k=1)[0]
    assert np.array_equal(ours, KDTree(targets).query(queries, k=1)[0])
    return np.asarray(ours)


def _terrain(rng: np.random.Generator, n: int, offset: float = 0.0) -> np.ndarray:
    xy = rng.uniform(0, 40, (n, 2))
    z = np.sin(xy[:, 0] / 5) + 0.3 * np.cos(xy[:, 1] / 3) + rng.normal(0, 0.05, n)
    return np.column_stack([xy, z]) + offset


def _lattice(rng: np.random.Generator, n: int, step: float = 0.2) -> np.ndarray:
    return np.unique(np.round(_terrain(rng, n) / step), axis=0) * step


def _sets() -> dict[str, tuple[np.ndarray, np.ndarray]]:
    rng = np.random.default_rng(11)
    cloud, lattice = _terrain(rng, 30_000), _lattice(rng, 20_000)
    centres = lattice[:3000] + 0.1  # equidistant from 8 lattice points: exact ties
    return {
        "cloud to lattice corners": (cloud, lattice),
        "lattice corners to cloud": (lattice, cloud),
        "lattice to itself and cell centres": (np.vstack([lattice, centres]), lattice),
        "dense cloud to sparse corners": (cloud, _lattice(rng, 800, step=1.4)),
        "flat set (zero height extent)": (cloud, np.column_stack([cloud[:5000, :2],
                                                                  np.zeros(5000)])),
        "UTM-sized coordinates": (_terrain(rng, 5000, 5e6), _terrain(rng, 4000, 5e6)),
        "one target": (cloud[:2000], cloud[:1]),
    }


@pytest.mark.parametrize("case", list(_sets()))
def test_distances_equal_kdtrees_bit_for_bit(case):
    queries, targets = _sets()[case]
    assert np.array_equal(nearest_distances(queries, targets), _reference(queries, targets))


def test_far_queries_go_to_coarser_grids_and_stay_exact():
    rng = np.random.default_rng(5)
    targets = _terrain(rng, 20_000)
    far = rng.normal(0, 1, (500, 3)) * 10 + np.array([300.0, -200.0, 50.0])
    queries = np.vstack([_terrain(rng, 3000), far])
    box = bounds(targets)
    first = build_grid(targets, first_side(box, len(targets)), box)
    _, settled = query_grid(first, queries, RINGS)
    assert settled[:3000].all() and not settled[3000:].any()
    assert np.array_equal(nearest_distances(queries, targets), _reference(queries, targets))


def test_crowded_targets_go_to_the_kdtree(monkeypatch):
    rng = np.random.default_rng(6)
    targets = np.vstack([np.zeros((5000, 3)) + rng.normal(0, 1e-4, (5000, 3)),
                         [[100.0, 100.0, 100.0]]])
    queries = rng.normal(0, 1, (2000, 3))
    box = bounds(targets)
    assert build_grid(targets, 1.0, box).load > MAX_LOAD
    calls = []

    class Counted(KDTree):
        def query(self, q: np.ndarray, k: int = 1) -> tuple[np.ndarray, np.ndarray]:
            calls.append(len(q))
            return super().query(q, k=k)

    monkeypatch.setattr(nearest, "KDTree", Counted)
    assert np.array_equal(nearest_distances(queries, targets), _reference(queries, targets))
    assert calls == [2000]
    index = nearest.NearestIndex(targets)  # the tree is built once, then kept
    index.distances(queries[:10])
    tree = index._tree
    assert np.array_equal(index.distances(queries), _reference(queries, targets))
    assert index._tree is tree and calls == [2000, 10, 2000]


def test_grid_cells_hold_their_points():
    rng = np.random.default_rng(8)
    pts = _terrain(rng, 5000)
    box = bounds(pts)
    assert np.array_equal(box[0], pts.min(axis=0)) and np.array_equal(box[1], pts.max(axis=0))
    grid = build_grid(pts, 0.7, box)
    assert np.array_equal(np.sort(grid.points, axis=0), np.sort(pts, axis=0))
    cells = np.repeat(np.arange(grid.start.size - 1), np.diff(grid.start))
    index = np.column_stack(np.unravel_index(cells, tuple(grid.dims)))
    lo = grid.lo + index * grid.h
    assert np.all(grid.points >= lo - 1e-9) and np.all(grid.points <= lo + grid.h + 1e-9)
    occupancy = np.diff(grid.start)
    assert grid.load == pytest.approx(float(occupancy @ occupancy) / len(pts))


lattice_sets = st.integers(1, 40).flatmap(
    lambda n: arrays(np.float64, (n, 3), elements=st.integers(-6, 6).map(lambda v: v * 0.3)))


@settings(max_examples=80, deadline=None)
@given(lattice_sets, lattice_sets)
def test_small_lattice_sets_with_ties_equal_the_kdtree(queries, targets):
    threads = numba.get_num_threads()
    assert np.array_equal(nearest_distances(queries, targets), _reference(queries, targets))
    assert numba.get_num_threads() == threads  # one thread for a small set, then restored
