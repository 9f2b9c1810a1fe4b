"""Exact nearest neighbours among the live rows of a point array that grows at its end and
loses rows only by a mask: the LIO's local map (:mod:`alte.registration.localmap`).

A k-d tree over 170,000 map points costs 20 ms to build (half of it numpy's column
maximum and minimum over the points), and the map changes by a few hundred points a
scan. So the rows up to ``base`` keep the tree built when they were packed, the rows added
since get a small tree of their own, and a query asks both (the rows dropped since
masked out of the search) and merges their neighbours by distance. The neighbours are the
ones a single tree over the live rows returns, in the same order, with the same distances
(ties of exactly equal distance aside).

The trees are pykdtree's: on the LIO's queries (a few thousand points, 5-20 neighbours)
it answers in about 60 % of scipy's time with the same neighbours, and its ``mask``
skips dropped rows inside the search. It runs one OpenMP thread here: a scan's query is
too small to share, and a second thread spinning beside it raised the LIO's CPU by half
(whole ``sim_lan_2`` UAV mission: 24 CPU s on one thread, 36 on two).

Between the Kalman filter's iterations over one scan the map stays as it is and the scan's
points move by millimetres, so :meth:`SplitTree.query` asks the trees for a few
neighbours more than wanted and keeps the answer (:class:`_Last`). A later query of as many points
takes a row's neighbours from it when they provably have not changed: the row's point
moved by ``shift`` from where it was searched, every other map point was at least the
last neighbour's distance (or ``bound``) from there, so it is now at least that minus
``shift`` away; when the ``k`` nearest of the kept candidates, measured again, are all
nearer than that, they are the ``k`` nearest, and in this order. Only the other rows are
searched again; the answer is the one a search of every row gives (ties aside), at a
fraction of its cost (the LIO's planes: about four queries per scan).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from pykdtree.kdtree import KDTree
from threadpoolctl import ThreadpoolController

__all__ = ["SplitTree"]

#: The neighbours' distances (N, k; inf where missing) and rows (N, k; the row count
#: where missing).
Found = tuple[NDArray[np.float64], NDArray[np.int64]]


#: The OpenMP runtime pykdtree queries with (limited to one thread around each query).
_OPENMP = ThreadpoolController().select(user_api="openmp")


#: Points per leaf of the trees: pykdtree's default 16 made the LIO's queries (20
#: neighbours each) a quarter slower, with the same neighbours.
LEAF = 32


def _tree(points: NDArray[np.float64]) -> KDTree | None:
    return KDTree(np.ascontiguousarray(points), leafsize=LEAF) if len(points) else None


def _ask(tree: KDTree, live: NDArray[np.bool_], query: NDArray[np.float64], k: int,
         bound: float) -> Found:
    """The ``k`` nearest live rows of one tree within ``bound`` (rows of the tree's own
    points, ``len(live)`` where missing): the dropped rows are masked out of the search."""
    with _OPENMP.limit(limits=1):
        dist, found = tree.query(query, k=k, distance_upper_bound=bound, mask=~live)
    return (np.asarray(dist, dtype=np.float64).reshape(-1, k),
            np.asarray(found, dtype=np.int64).reshape(-1, k))


#: Neighbours searched beyond the ``k`` asked for: the farther the last of them, the more
#: rows keep their neighbours while their points move.
EXTRA = 6


@dataclass(frozen=True)
class _Last:
    """The last search: per row the point searched from and its ``k + EXTRA`` nearest."""

    query: NDArray[np.float64]
    dist: NDArray[np.float64]
    idx: NDArray[np.int64]
    bound: float


class SplitTree:
    """k-d trees over ``points[:base]`` (built once) and ``points[base:]`` (rebuilt on
    every :meth:`update`), queried as one tree over the ``live`` rows; the last search is
    kept for the next query (module docstring) until the rows change."""

    def __init__(self, points: NDArray[np.float64], live: NDArray[np.bool_]) -> None:
        self.base = len(points)
        self._packed = _tree(points)
        self._recent: KDTree | None = None
        self._last: _Last | None = None
        self.points, self.live = points, live

    def update(self, points: NDArray[np.float64], live: NDArray[np.bool_]) -> None:
        """Rows appended to ``points`` (its first ``base`` rows unchanged) or dropped from
        ``live``."""
        self.points, self.live = points, live
        self._recent = _tree(points[self.base:])
        self._last = None

    def query(self, query: NDArray[np.float64], k: int, bound: float) -> Found:
        """The ``k`` nearest live rows within ``bound`` of each query point, nearest first."""
        query = np.ascontiguousarray(query, dtype=np.float64)
        last = self._last
        if last is None or last.query.shape != query.shape or last.bound != bound \
                or last.idx.shape[1] != k + EXTRA or not len(self.points):
            dist, idx = self._search(query, k + EXTRA, bound)
            self._last = _Last(query.copy(), dist, idx, bound)
            return dist[:, :k].copy(), idx[:, :k].copy()
        from alte.registration.lio_kernels import kept_nearest  # numba: on first use

        kept, dist, idx = kept_nearest(np.ascontiguousarray(self.points), query,
                                       (last.query, last.dist, last.idx), bound, k)
        redo = np.flatnonzero(~kept)
        if len(redo):
            again = self._search(query[redo], k + EXTRA, bound)
            dist[redo], idx[redo] = again[0][:, :k], again[1][:, :k]
            anchor, near, rows = last.query.copy(), last.dist.copy(), last.idx.copy()
            anchor[redo], near[redo], rows[redo] = query[redo], again[0], again[1]
            self._last = _Last(anchor, near, rows, bound)
        return dist, idx

    def _search(self, query: NDArray[np.float64], k: int, bound: float) -> Found:
        """The trees' ``k`` nearest live rows within ``bound`` of each query point."""
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
        from alte.registration.lio_kernels import merge_nearest  # numba: on first use

        return merge_nearest(found[0], found[1])
