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

