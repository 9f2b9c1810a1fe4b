"""The compiled 2D cell lookup (alte.metrics.cellxy) against the numpy one it replaced."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from alte.metrics.cellxy import cell_at_xy, lattice_keys, size_groups


def _numpy_cell_at_xy(xy: NDArray[np.float64], centers: NDArray[np.float64],
                      sizes: NDArray[np.float64]) -> NDArray[np.int64]:
    """The lookup as numpy array operations (the former implementation), the reference."""
    found = np.full(len(xy), -1, dtype=np.int64)
    half = sizes[:, :2] / 2.0
    groups, inverse = size_groups(half)
    for g, h in enumerate(groups):
        sel = np.flatnonzero(inverse.reshape(-1) == g)
        step = np.maximum(2.0 * h, 1e-12)
        origin = centers[sel[0], :2] - h
        keys = lattice_keys(np.rint((centers[sel, :2] - h - origin) / step).astype(np.int64))
        order = np.argsort(keys)
        sorted_keys = keys[order]
        todo = np.flatnonzero(found < 0)
        rel = (xy[todo] - origin) / step
        low = np.floor(rel)
        on_edge = (low == rel).astype(np.int64)
        for shift in ((0, 0), (1, 0), (0, 1), (1, 1)):
            rows = np.all(on_edge >= shift, axis=1)
            pts = todo[rows]
            with np.errstate(invalid="ignore"):  # NaN points: no key, no cell
                query = lattice_keys(low[rows].astype(np.int64) - np.asarray(shift))
            pos = np.minimum(np.searchsorted(sorted_keys, query), len(sorted_keys) - 1)
            cand = sel[order[pos]]
            inside = ((sorted_keys[pos] == query) & (found[pts] < 0)
                      & np.all(np.abs(xy[pts] - centers[cand, :2]) <= h + 1e-9, axis=1))
            found[pts[inside]] = cand[inside]
    return found


def _quadtree_leaves(seed: int) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Leaves of a random quadtree (many sizes, shared edges) over [0, 8) x [0, 8)."""
    rng = np.random.default_rng(seed)
    todo, centers, sizes = [(4.0, 4.0, 8.0)], [], []
    while todo:
        x, y, s = todo.pop()
        if s > 0.25 and rng.random() < 0.7:
            q = s / 4
            todo += [(x - q, y - q, s / 2), (x + q, y - q, s / 2), (x - q, y + q, s / 2),
                     (x + q, y + q, s / 2)]
        else:
            centers.append((x, y, rng.normal()))
            sizes.append((s, s, 0.0))
    return np.array(centers), np.array(sizes)


def test_the_compiled_lookup_equals_the_numpy_one_on_random_trees():
    """Random quadtrees, probes inside, outside, on edges and corners (a 0.125 m grid
    hits every edge) and NaN: the same cell for every point."""
    for seed in range(4):
        centers, sizes = _quadtree_leaves(seed)
        rng = np.random.default_rng(seed)
        grid = np.stack(np.meshgrid(np.arange(-0.5, 8.6, 0.125), np.arange(-0.5, 8.6, 0.125)),
                        axis=-1).reshape(-1, 2)
        xy = np.vstack([rng.uniform(-1, 9, (2000, 2)), grid,
                        centers[:, :2] + sizes[:, :2] / 2, [[np.nan, 1.0]]])
        want = _numpy_cell_at_xy(xy, centers, sizes)
        np.testing.assert_array_equal(cell_at_xy(xy, centers, sizes), want)
        assert (want >= 0).sum() > 2000  # most probes lie in the tree


def test_a_point_no_cell_holds_gets_minus_one_and_empty_inputs_give_nothing():
    centers, sizes = np.array([[0.5, 0.5, 0.0]]), np.array([[1.0, 1.0, 0.0]])
    assert cell_at_xy(np.array([[1.0 + 1e-6, 0.5]]), centers, sizes).tolist() == [-1]
    near = np.array([[1.0 + 1e-10, 0.5], [1.0 - 1e-10, 0.5], [0.0, 0.0], [1.0, 1.0]])
    assert cell_at_xy(near, centers, sizes).tolist() == [-1, 0, 0, 0]  # the lattice decides
    assert cell_at_xy(np.empty((0, 2)), centers, sizes).shape == (0,)
    assert cell_at_xy(np.zeros((2, 2)), np.empty((0, 3)), np.empty((0, 3))).tolist() == [-1, -1]
