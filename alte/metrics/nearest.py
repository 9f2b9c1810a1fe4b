"""Nearest-target distances of many queries: the grid search of
:mod:`~alte.metrics._gridnn`, coarser grids for what it leaves, pykdtree past them.

The one nearest-neighbour search of the metrics (HD/MHD, a reference's cloud).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from pykdtree.kdtree import KDTree

from alte.metrics._gridnn import (
    COARSER,
    MAX_LOAD,
    RINGS,
    CellIndex,
    bounds,
    build_grid,
    first_side,
    query_grid,
)

__all__ = ["NearestIndex", "nearest_distances"]


class NearestIndex:
    """Targets (N, 3) prepared once for any number of nearest-distance queries: the first
    grid is built at once, each coarser one (and pykdtree's tree) when a query first needs
    it, then kept (a
    sweep measures every map of one input against the same cloud: one build, not one per
    map). The distances are :func:`nearest_distances`'s."""

    def __init__(self, targets: NDArray[np.float64]) -> None:
        self.targets = targets
        self.box: tuple[NDArray[np.float64], NDArray[np.float64]] = bounds(targets)
        self.grids = [build_grid(targets, first_side(self.box, len(targets)), self.box)]
        self._tree: KDTree | None = None

    def _kdtree(self, queries: NDArray[np.float64]) -> NDArray[np.float64]:
        """The queries the grids leave to pykdtree (its tree built once, then kept)."""
        if self._tree is None:
            self._tree = KDTree(self.targets)
        return np.asarray(self._tree.query(queries, k=1)[0], dtype=np.float64)

    def _grid(self, i: int) -> CellIndex:
        if i == len(self.grids):
            self.grids.append(build_grid(self.targets, self.grids[-1].h * COARSER, self.box))
        return self.grids[i]

    def distances(self, queries: NDArray[np.float64]) -> NDArray[np.float64]:
        """Distance from every query (M, 3) to its nearest target (finite float64)."""
        grid = self.grids[0]
        if grid.load > MAX_LOAD:
            return self._kdtree(queries)
        dist, settled = query_grid(grid, queries, RINGS)
        todo = np.flatnonzero(~settled)
        level = 0
        while todo.size:
            level += 1
            grid = self._grid(level)
            if grid.load > MAX_LOAD:
                dist[todo] = self._kdtree(queries[todo])
                break
            found, settled = query_grid(grid, queries[todo], RINGS)
            dist[todo] = found
            todo = todo[~settled]
        return dist


def nearest_distances(queries: NDArray[np.float64], targets: NDArray[np.float64],
                      ) -> NDArray[np.float64]:
    """Distance from every query (M, 3) to its nearest target (N, 3); finite float64 sets."""
    return NearestIndex(targets).distances(queries)
