"""Exact nearest neighbours among the live rows of a point array that grows at its end and
loses rows only by a mask: the LIO's local map (:mod:`alte.registration.localmap`).

A k-d tree over 170,000 map points costs 20 ms to build (half of it numpy's column
maximum and minimum over the points), and the map changes by a few hundred points a
scan. So the rows up to ``base`` keep the tree built when they were packed, the rows added
since get a small tree of their own, and a query asks both and merges their neighbours by
distance; a neighbour among the rows dropped since is skipped and its query asked again
deeper in its tree. The neighbours are the ones a single tree over the live rows returns,
in the same order, with the same distances (ties of exactly equal distance aside).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from scipy.spatial import cKDTree

__all__ = ["SplitTree"]

#: The neighbours' distances (N, k; inf where missing) and rows (N, k; the row count
#: where missing).
Found = tuple[NDArray[np.float64], NDArray[np.int64]]


def _tree(points: NDArray[np.float64]) -> cKDTree | None:
    return cKDTree(points, balanced_tree=False, compact_nodes=False) if len(points) else None


def _ask(tree: cKDTree, live: NDArray[np.bool_], query: NDArray[np.float64], k: int,
         bound: float) -> Found:
    """The ``k`` nearest live rows of one tree within ``bound`` (rows of the tree's own
    points, ``len(live)`` where missing); a query that met dropped rows asks again for
    twice as many, until it holds ``k`` live ones or every row within ``bound``."""
    dist, found = tree.query(query, k=k, distance_upper_bound=bound)
    dist = np.asarray(dist, dtype=np.float64).reshape(-1, k)
    idx = np.asarray(found, dtype=np.int64).reshape(-1, k)
    alive = np.append(live, True)  # the missing row counts as live (and inf away)
    rows = np.flatnonzero(~alive[idx].all(axis=1))
    deeper = k
    while len(rows):
        deeper = min(2 * deeper, max(len(live), k))
        more, again = tree.query(query[rows], k=deeper, distance_upper_bound=bound)
        more = np.asarray(more, dtype=np.float64).reshape(-1, deeper)
        again = np.asarray(again, dtype=np.int64).reshape(-1, deeper)
        exhausted = np.isinf(more[:, -1]) | (deeper >= len(live))  # all within bound
        more[~alive[again]] = np.inf
        order = np.argsort(more, axis=1, kind="stable")[:, :k]
        dist[rows] = np.take_along_axis(more, order, axis=1)
        idx[rows] = np.take_along_axis(again, order, axis=1)
        rows = rows[~(exhausted | (np.isfinite(more).sum(axis=1) >= k))]
    idx[np.isinf(dist)] = len(live)
    return dist, idx


class SplitTree:
    """k-d trees over ``points[:base]`` (built once) and ``points[base:]`` (rebuilt on
    every :meth:`update`), queried as one tree over the ``live`` rows."""

    def __init__(self, points: NDArray[np.float64], live: NDArray[np.bool_]) -> None:
        self.base = len(points)
        self._packed = _tree(points)
        self._recent: cKDTree | None = None
        self.points, self.live = points, live

    def update(self, points: NDArray[np.float64], live: NDArray[np.bool_]) -> None:
        """Rows appended to ``points`` (its first ``base`` rows unchanged) or dropped from
        ``live``."""
        self.points, self.live = points, live
        self._recent = _tree(points[self.base:])

    def query(self, query: NDArray[np.float64], k: int, bound: float) -> Found:
        """The ``k`` nearest live rows within ``bound`` of each query point, nearest first."""
        total = len(self.points)
        parts = [(tree, offset, self.live[offset:end]) for tree, offset, end in
                 ((self._packed, 0, self.base), (self._recent, self.base, total))
                 if tree is not None]
        found = []
        for tree, offset, live in parts:
            dist, idx = _ask(tree, live, query, k, bound)
            found.append((dist, np.where(idx == len(live), total, idx + offset)))
        if len(found) <= 1:
            return found[0] if found else (np.full((len(query), k), np.inf),
                                           np.full((len(query), k), total, np.int64))
        dist, idx = np.hstack([f[0] for f in found]), np.hstack([f[1] for f in found])
        order = np.argsort(dist, axis=1, kind="stable")[:, :k]
        return np.take_along_axis(dist, order, axis=1), np.take_along_axis(idx, order, axis=1)
