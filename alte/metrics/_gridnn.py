"""Exact nearest-neighbour distances on a uniform grid of cells, with a KD-tree fallback.

The targets are counting-sorted into cubic cells of side ``h``. A query scans its own
cell (else rings of cells around it until one holds a target), then every cell that the
ball through the best target so far reaches, skipping cells whose nearest wall is already
no nearer. Walls and cell indices carry a tolerance far above their rounding, so no
target that could be nearer is skipped: the result is the exact minimum. Squared
distances are summed x, y, z in float64 and square-rooted, as pykdtree, scipy and open3d
(nanoflann) do, so the distances are theirs to the last bit. On terrain clouds and map
corners a query touches about three cells and two dozen points, about half the work of a
KD-tree descent with backtracking (``environment.md`` has the measurements).

The first grid has the smallest cells keeping it within :data:`CELLS_PER_TARGET` cells
per target (linear build, little memory). A query with no target within :data:`RINGS`
rings of its cell goes to a grid :data:`COARSER` times coarser, and so on; once the
targets crowd the cells (:data:`MAX_LOAD`) a pykdtree KD-tree answers the rest
(:mod:`~alte.metrics.nearest` chains them).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TypeAlias

import numba
import numpy as np
from numpy.typing import NDArray

from alte._kernels import bounds
from alte._numba import threads_for

__all__ = ["CELLS_PER_TARGET", "COARSER", "MAX_LOAD", "PARALLEL_MIN", "RINGS", "CellIndex",
           "bounds", "build_grid", "first_side", "query_grid"]

#: Cells allowed per target point: the dense cell index costs O(cells + points);
#: fewer, fuller cells were faster on the benchmark's clouds than emptier ones.
CELLS_PER_TARGET = 0.5
#: Rings of cells searched around a query's cell before it goes to a coarser grid.
RINGS = 3
#: Cell side ratio of one grid to the next.
COARSER = 4.0
#: Largest mean number of targets sharing a target's cell; a more crowded grid (each
#: query would scan whole clusters) leaves the remaining queries to the KD-tree.
MAX_LOAD = 256.0
#: Fewer queries than this run on one thread: waking a second one costs more than it saves.
PARALLEL_MIN = 4096
#: Tolerance on cell walls, relative to the coordinates (far above their rounding).
_TOL = 1e-9
#: Coordinates are clamped to this many cells from the grid before the integer cast.
_FAR = 2.0**40
#: Cell index ranges (first, last along x, then y, then z).
Range = tuple[int, int, int, int, int, int]
#: Coordinates and distances (float64), cell counts and starts (int64), as the kernels take them.
Floats: TypeAlias = NDArray[np.float64]
Ints: TypeAlias = NDArray[np.int64]

@dataclass(frozen=True)
class CellIndex:
    """Targets sorted by cell: cell ``c`` holds ``points[start[c]:start[c + 1]]``.

    ``load`` is the mean number of targets in a target's cell (the cost of scanning one);
    ``scale`` the largest absolute target coordinate (for the walls' tolerance).
    """

    lo: Floats
    h: float
    dims: Ints
    start: Ints
    points: Floats
    load: float
    scale: float


@numba.njit(cache=True)
def _bucket(points: Floats, lo: Floats, h: float,
            dims: Ints) -> tuple[Ints, Floats, float]:
    """Counting sort of ``points`` by cell: (cell starts, points in cell order, load)."""
    n = points.shape[0]
    cell = np.empty(n, np.int64)
    start = np.zeros(dims[0] * dims[1] * dims[2] + 1, np.int64)
    for i in range(n):
        c = 0
        for a in range(3):
            c = c * dims[a] + min(max(int((points[i, a] - lo[a]) / h), 0), dims[a] - 1)
        cell[i] = c
        start[c + 1] += 1
    load = 0.0
    for c in range(start.size - 1):
        load += float(start[c + 1]) ** 2
        start[c + 1] += start[c]
    fill = start[:-1].copy()
    out = np.empty((n, 3))
    for i in range(n):
        f = fill[cell[i]]
        out[f, 0], out[f, 1], out[f, 2] = points[i, 0], points[i, 1], points[i, 2]
        fill[cell[i]] = f + 1
    return start, out, load / max(n, 1)


@numba.njit(cache=True, inline="always")
def _cell(q: float, lo: float, h: float) -> int:
    """Index of the cell holding coordinate ``q`` along one axis (may lie off the grid)."""
    return int(np.floor(min(max((q - lo) / h, -_FAR), _FAR)))


@numba.njit(cache=True, inline="always")
def _gap2(q: float, lo: float, h: float, j: int, tol: float) -> float:
    """Squared distance from ``q`` to cell slab ``j`` along one axis, less ``tol`` (so a
    safe lower bound whatever the rounding of the walls and of the bucketing)."""
    a = lo + j * h
    g = (a - q if q < a else q - (a + h)) - tol
    return g * g if g > 0.0 else 0.0


@numba.njit(cache=True, inline="always")
def _scan(  # noqa: PLR0917 - a numba kernel's scalars and arrays
    q0: float, q1: float, q2: float, pts: Floats, first: int, last: int, best: float,
) -> float:
    """Smallest squared distance from ``q`` to ``pts[first:last]``, or ``best``."""
    for p in range(first, last):
        d0 = q0 - pts[p, 0]
        d1 = q1 - pts[p, 1]
        d2 = q2 - pts[p, 2]
        d = d0 * d0 + d1 * d1 + d2 * d2
        best = min(best, d)
    return best


@numba.njit(cache=True, inline="always")
def _block(  # noqa: PLR0917 - a numba kernel's scalars and arrays
    q0: float, q1: float, q2: float, c0: int, c1: int, c2: int, skip: int, rng: Range,
    lo: Floats, h: float, dims: Ints, start: Ints, pts: Floats,
    best: float, tol: float,
) -> float:
    """Scan the cells in ``rng`` (first, last along x, y, z) nearer than ``best``, except
    those within Chebyshev distance ``skip`` of cell ``c`` (already searched)."""
    for i0 in range(rng[0], rng[1] + 1):
        g0 = _gap2(q0, lo[0], h, i0, tol)
        if g0 >= best:
            continue
        for i1 in range(rng[2], rng[3] + 1):
            g01 = g0 + _gap2(q1, lo[1], h, i1, tol)
            if g01 >= best:
                continue
            near = max(abs(i0 - c0), abs(i1 - c1)) <= skip
            base = (i0 * dims[1] + i1) * dims[2]
            for i2 in range(rng[4], rng[5] + 1):
                if (near and abs(i2 - c2) <= skip) or g01 + _gap2(q2, lo[2], h, i2,
                                                                  tol) >= best:
                    continue
                best = _scan(q0, q1, q2, pts, start[base + i2], start[base + i2 + 1], best)
    return best


@numba.njit(cache=True, inline="always")
def _around(  # noqa: PLR0917 - a numba kernel's scalars and arrays
    q0: float, q1: float, q2: float, r: float, lo: Floats, h: float, dims: Ints,
) -> Range:
    """Cell ranges (first, last along x, y, z) of the grid meeting the cube ``q`` +- ``r``."""
    return (max(_cell(q0 - r, lo[0], h), 0), min(_cell(q0 + r, lo[0], h), dims[0] - 1),
            max(_cell(q1 - r, lo[1], h), 0), min(_cell(q1 + r, lo[1], h), dims[1] - 1),
            max(_cell(q2 - r, lo[2], h), 0), min(_cell(q2 + r, lo[2], h), dims[2] - 1))


@numba.njit(cache=True)
def _first_hit(  # noqa: PLR0917 - a numba kernel's scalars and arrays
    q0: float, q1: float, q2: float, c0: int, c1: int, c2: int, lo: Floats, h: float,
    dims: Ints, start: Ints, pts: Floats, rings: int, tol: float,
) -> tuple[float, int]:
    """(best squared distance, ring) from the first of rings 1..``rings`` around cell ``c``
    that holds a target; (inf, rings) when none does."""
    best = np.inf
    for k in range(1, rings + 1):
        ring = (max(c0 - k, 0), min(c0 + k, dims[0] - 1), max(c1 - k, 0),
                min(c1 + k, dims[1] - 1), max(c2 - k, 0), min(c2 + k, dims[2] - 1))
        best = _block(q0, q1, q2, c0, c1, c2, k - 1, ring, lo, h, dims, start, pts, best, tol)
        if best < np.inf:
            return best, k
    return best, rings


@numba.njit(cache=True, inline="always")
def _nearest(  # noqa: PLR0917 - a numba kernel's scalars and arrays
    q0: float, q1: float, q2: float, lo: Floats, h: float, dims: Ints,
    start: Ints, pts: Floats, rings: int, scale: float,
) -> float:
    """Squared distance to the nearest target, or inf when none lies within ``rings`` rings.

    The query's own cell is searched, else rings of cells around it until one holds a
    target; then every cell the ball through the best target so far reaches.
    """
    tol = _TOL * (1.0 + scale + max(abs(q0), abs(q1), abs(q2)))
    c0, c1, c2 = _cell(q0, lo[0], h), _cell(q1, lo[1], h), _cell(q2, lo[2], h)
    best, done = np.inf, 0
    if 0 <= c0 < dims[0] and 0 <= c1 < dims[1] and 0 <= c2 < dims[2]:
        own = (c0 * dims[1] + c1) * dims[2] + c2
        best = _scan(q0, q1, q2, pts, start[own], start[own + 1], best)
    if best == np.inf:
        best, done = _first_hit(q0, q1, q2, c0, c1, c2, lo, h, dims, start, pts, rings, tol)
        if best == np.inf:
            return best
    box = _around(q0, q1, q2, np.sqrt(best) + tol, lo, h, dims)
    return _block(q0, q1, q2, c0, c1, c2, done, box, lo, h, dims, start, pts, best, tol)


@numba.njit(cache=True, parallel=True)
def _query(  # noqa: PLR0917 - a numba kernel's scalars and arrays
    queries: Floats, lo: Floats, h: float, dims: Ints, start: Ints,
    pts: Floats, rings: int, scale: float,
) -> tuple[Floats, NDArray[np.bool_]]:
    m = queries.shape[0]
    dist = np.empty(m)
    settled = np.empty(m, np.bool_)
    for i in numba.prange(m):
        d2 = _nearest(queries[i, 0], queries[i, 1], queries[i, 2], lo, h, dims, start, pts,
                      rings, scale)
        dist[i] = np.sqrt(d2)
        settled[i] = d2 < np.inf
    return dist, settled


def _side_for_cells(extent: Floats, cells: float, smallest: float) -> float:
    """Smallest cell side (at least ``smallest``) whose grid over ``extent`` has at most
    ``cells`` cells."""
    top = float(extent.max())
    if top <= smallest:
        return smallest

    def count(h: float) -> float:
        return float(np.prod(np.maximum(np.ceil(extent / h), 1)))

    lo, hi = max(top / (cells + 1), smallest), top
    for _ in range(60):
        mid = np.sqrt(lo) * np.sqrt(hi)
        lo, hi = (mid, hi) if count(mid) > cells else (lo, mid)
    return hi


def first_side(box: tuple[Floats, Floats], n: int) -> float:
    """Cell side of the first grid of ``n`` targets in ``box`` (module docstring); never
    below a thousand times the wall tolerance, where pruning cells would stop paying."""
    scale = float(max(np.abs(box[0]).max(), np.abs(box[1]).max()))
    return _side_for_cells(box[1] - box[0], CELLS_PER_TARGET * n, 1e3 * _TOL * (1.0 + scale))


def build_grid(points: Floats, h: float, box: tuple[Floats, Floats]) -> CellIndex:
    """Bucket ``points`` (N, 3) into cells of side ``h`` over their bounding ``box``."""
    lo, hi = box
    dims = np.maximum(np.ceil((hi - lo) / h), 1).astype(np.int64)
    start, ordered, load = _bucket(points, lo, h, dims)
    scale = float(max(np.abs(lo).max(), np.abs(hi).max()))
    return CellIndex(lo, h, dims, start, ordered, load, scale)


def query_grid(grid: CellIndex, queries: Floats, rings: int,
               ) -> tuple[Floats, NDArray[np.bool_]]:
    """(distance to the nearest target, settled) for every query (M, 3): exact where
    settled, inf where no target lies within ``rings`` rings of the query's cell."""
    with threads_for(len(queries), PARALLEL_MIN):
        return _query(queries, grid.lo, grid.h, grid.dims, grid.start, grid.points, rings,
                      grid.scale)
