"""The LIO map's split k-d tree: the neighbours one tree over the live rows gives, in order,
with rows appended and dropped between queries, and trees smaller than k."""

import numpy as np
import pytest
from scipy.spatial import cKDTree

from alte.registration.neighbours import SplitTree


def _single(points, live, query, k, bound):
    """What one k-d tree over the live rows says, in row numbers of ``points``."""
    rows = np.flatnonzero(live)
    dist, idx = cKDTree(points[rows]).query(query, k=k, distance_upper_bound=bound)
    dist, idx = dist.reshape(len(query), k), idx.reshape(len(query), k)
    return dist, np.where(np.isinf(dist), len(points), np.append(rows, len(points))[idx])


@pytest.mark.parametrize(("base", "added", "k"), [(3000, 400, 20), (3000, 7, 20), (12, 5, 20)])
def test_split_tree_finds_the_live_neighbours_a_single_tree_finds(base, added, k):
    """Rows packed under one tree, more appended under another, a fifth of them dropped
    (most near the probes, so queries must look deeper): same distances, same rows."""
    rng = np.random.default_rng(3)
    points = rng.uniform(-5, 5, (base, 3))
    index = SplitTree(points, np.ones(base, bool))
    points = np.vstack([points, rng.uniform(-5, 5, (added, 3))])
    live = rng.random(len(points)) > 0.2
    near = np.linalg.norm(points, axis=1) < 1.5
    live[near] &= rng.random(near.sum()) > 0.7
    index.update(points, live)
    query = rng.uniform(-5, 5, (300, 3))
    dist, idx = index.query(query, k, 2.0)
    want_dist, want_idx = _single(points, live, query, k, 2.0)
    assert np.array_equal(dist, want_dist)
    assert np.array_equal(idx, want_idx)
    assert live[idx[np.isfinite(dist)]].all()


def test_an_empty_split_tree_finds_nothing():
    dist, idx = SplitTree(np.empty((0, 3)), np.empty(0, bool)).query(np.zeros((2, 3)), 5, 1.0)
    assert np.isinf(dist).all() and (idx == 0).all()



def _moved(index, points, live, steps):
    """Query the same points moved by ``steps`` (m) in turn; each answer beside one tree's."""
    k, bound = 20, 3.0
    rng = np.random.default_rng(5)
    query = rng.uniform(-4, 4, (400, 3))
    for step in steps:
        query = query + rng.normal(0.0, step, query.shape)
        dist, idx = index.query(query, k, bound)
        want_dist, want_idx = _single(points, live, query, k, bound)
        assert np.array_equal(dist, want_dist), step
        assert np.array_equal(idx, want_idx), step


@pytest.mark.parametrize("steps", [(0.0, 1e-4, 1e-3, 0.0), (0.05, 0.01, 0.3, 2.0)])
def test_moved_queries_find_what_a_fresh_search_finds(steps):
    """A query of as many points as the last one keeps the neighbours of the rows that
    provably did not change: from no move to moves past the neighbours' spacing (most
    rows searched again), always the neighbours a fresh search gives, in order."""
    rng = np.random.default_rng(4)
    points = rng.uniform(-5, 5, (4000, 3))
    live = rng.random(len(points)) > 0.1
    index = SplitTree(points, np.ones(len(points), bool))
    index.update(points, live)
    _moved(index, points, live, (0.0, *steps))


def test_small_moves_search_only_the_rows_that_may_have_changed(monkeypatch):
    """Points moved by micrometres keep (nearly) all their neighbours: the trees are asked
    again for a few rows at most, and after the map changes for every row."""
    rng = np.random.default_rng(6)
    points = rng.uniform(-5, 5, (4000, 3))
    live = np.ones(len(points), bool)
    index = SplitTree(points, live)
    asked = []
    search = SplitTree._search
    monkeypatch.setattr(SplitTree, "_search",
                        lambda self, q, k, b: asked.append(len(q)) or search(self, q, k, b))
    query = rng.uniform(-4, 4, (400, 3))
    index.query(query, 20, 3.0)
    index.query(query + 1e-6, 20, 3.0)
    live[:10] = False
    index.update(points, live)
    index.query(query + 1e-6, 20, 3.0)
    assert asked[0] == 400 and asked[-1] == 400
    assert sum(asked[1:-1]) <= 4, asked


def test_equal_distances_are_searched_again():
    """On a lattice many neighbours lie at exactly equal distances, whose order is the
    trees': moved probes get the rows and order of a fresh search of a new tree."""
    grid = np.stack(np.meshgrid(*[np.arange(-6.0, 7.0)] * 3, indexing="ij"), -1).reshape(-1, 3)
    live = np.ones(len(grid), bool)
    index = SplitTree(grid, live)
    query = np.repeat(np.array([[0.0, 0.0, 0.0], [0.5, 0.5, 0.0], [1.0, 2.0, 0.5]]), 3, axis=0)
    for move in (0.0, 1e-12, 0.0):
        query = query + move
        dist, idx = index.query(query, 20, 3.0)
        want = SplitTree(grid, live).query(query, 20, 3.0)
        assert np.array_equal(dist, want[0]) and np.array_equal(idx, want[1])
