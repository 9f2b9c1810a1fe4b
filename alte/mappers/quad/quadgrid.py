"""Sparse per-level cell statistics on a square domain: the engine of the 2D mappers.

Level ``l`` divides the square root domain into ``2^l x 2^l`` cells; a cell is named
by the Morton key of its integer indices, so a parent's key is its child's key
``>> 2`` and sorted child keys group by parent. For every level ``0..depth`` we keep
the sorted keys of the non-empty cells and, per cell, the count ``n`` and for each
value column its mean, ``M2`` (sum of squared deviations, merged with Chan's parallel
formula: no cancellation when heights are equal) and maximum.

Adding points sorts them once at the finest level and merges aggregates upwards, so
the arithmetic is proportional to the new points (times the depth); the statistics
live in :class:`alte.mappers.quad.levelstats.LevelStats`.
The statistics of a cloud do not depend on how it was cut into
frames (up to floating-point rounding of the sums), which is what makes the mappers'
incremental insertion equal their batch build.
"""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np
from numpy.typing import NDArray

from alte._numba import CLOUD_MIN, threads_for
from alte.types import rows_all

__all__ = ["Square", "morton_decode", "morton_encode"]



def _part1by1(index: NDArray[np.int64]) -> NDArray[np.uint64]:
    v = index.astype(np.uint64) & np.uint64(0x00000000FFFFFFFF)
    for shift, mask in ((16, 0x0000FFFF0000FFFF), (8, 0x00FF00FF00FF00FF),
                        (4, 0x0F0F0F0F0F0F0F0F), (2, 0x3333333333333333),
                        (1, 0x5555555555555555)):
        v = (v | (v << np.uint64(shift))) & np.uint64(mask)
    return v


def _compact1by1(v: NDArray[np.uint64]) -> NDArray[np.uint64]:
    v = v.astype(np.uint64) & np.uint64(0x5555555555555555)
    for shift, mask in ((1, 0x3333333333333333), (2, 0x0F0F0F0F0F0F0F0F),
                        (4, 0x00FF00FF00FF00FF), (8, 0x0000FFFF0000FFFF),
                        (16, 0x00000000FFFFFFFF)):
        v = (v | (v >> np.uint64(shift))) & np.uint64(mask)
    return v


@numba.njit(cache=True, inline="always")
def _spread(v: int) -> int:
    """:func:`_part1by1` of one index below 2^32."""
    v &= 0x00000000FFFFFFFF
    v = (v | (v << 16)) & 0x0000FFFF0000FFFF
    v = (v | (v << 8)) & 0x00FF00FF00FF00FF
    v = (v | (v << 4)) & 0x0F0F0F0F0F0F0F0F
    v = (v | (v << 2)) & 0x3333333333333333
    return (v | (v << 1)) & 0x5555555555555555


@numba.njit(cache=True, parallel=True)
def _locate(xy: NDArray[np.float64], corner: tuple[float, float], size: float,
            cells: int) -> tuple[NDArray[np.int64], NDArray[np.bool_]]:
    """Morton keys of ``xy``'s cells (clipped to the grid) and whether each point lies in
    the closed square: :meth:`Square.keys` and :meth:`Square.contains` in one pass (on
    every thread for a whole cloud: ``alte._numba.CLOUD_MIN``)."""
    keys = np.empty(xy.shape[0], dtype=np.int64)
    inside = np.empty(xy.shape[0], dtype=np.bool_)
    for i in numba.prange(xy.shape[0]):
        rx, ry = (xy[i, 0] - corner[0]) / size, (xy[i, 1] - corner[1]) / size
        inside[i] = rx >= 0.0 and rx <= 1.0 and ry >= 0.0 and ry <= 1.0
        ix = min(max(np.floor(rx * cells), 0.0), cells - 1.0)
        iy = min(max(np.floor(ry * cells), 0.0), cells - 1.0)
        keys[i] = _spread(int(ix)) | (_spread(int(iy)) << 1)
    return keys, inside


def morton_encode(ix: NDArray[np.int64], iy: NDArray[np.int64]) -> NDArray[np.int64]:
    """Interleave cell indices (x in the even bits) into int64 keys."""
    keys: NDArray[np.int64] = (_part1by1(ix) | (_part1by1(iy) << np.uint64(1))).astype(np.int64)
    return keys


def morton_decode(keys: NDArray[np.int64]) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """Inverse of :func:`morton_encode`."""
    k = np.asarray(keys).astype(np.uint64)
    return (_compact1by1(k).astype(np.int64), _compact1by1(k >> np.uint64(1)).astype(np.int64))


@numba.njit(cache=True)
def _extent(xy: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Per-column minimum and maximum of (N >= 1, 2) finite points, in one pass (numpy
    reduces an (N, 2) array along axis 0 two values at a time, and a strided column
    at a time reads every row's cache line); the four bounds stay in registers."""
    x0 = x1 = xy[0, 0]
    y0 = y1 = xy[0, 1]
    for i in range(1, xy.shape[0]):
        x, y = xy[i, 0], xy[i, 1]
        x0, x1, y0, y1 = min(x0, x), max(x1, x), min(y0, y), max(y1, y)
    return np.array([x0, y0]), np.array([x1, y1])


@dataclass(frozen=True)
class Square:
    """The root cell ``[xmin, xmin + size] x [ymin, ymin + size]`` (closed)."""

    xmin: float
    ymin: float
    size: float

    @classmethod
    def bounding(cls, xy: NDArray[np.float64]) -> Square:
        """Smallest square anchored at the minimum corner holding ``xy`` (size 1 if a point)."""
        lo, hi = _extent(xy)
        size = float((hi - lo).max())
        return cls(float(lo[0]), float(lo[1]), size if size > 0 else 1.0)

    @classmethod
    def dyadic(cls, xy: NDArray[np.float64]) -> Square:
        """Power-of-two square on a grid of its own size holding ``xy`` (root of a growing map)."""
        lo, hi = _extent(xy)
        extent = float((hi - lo).max())
        size = float(np.exp2(np.ceil(np.log2(extent)))) if extent > 0 else 1.0
        xmin, ymin = np.floor(lo / size) * size
        return cls(float(xmin), float(ymin), size)

    def contains(self, xy: NDArray[np.float64], closed: bool = True) -> NDArray[np.bool_]:
        """Mask of the points inside the square; ``closed=False`` excludes the upper edges."""
        rel = (xy - (self.xmin, self.ymin)) / self.size
        upper = (rel <= 1.0) if closed else (rel < 1.0)
        inside: NDArray[np.bool_] = rows_all((rel >= 0.0) & upper)
        return inside

    def locate(self, xy: NDArray[np.float64], level: int,
               ) -> tuple[NDArray[np.int64], NDArray[np.bool_]]:
        """:meth:`keys` and :meth:`contains` (closed) of ``xy`` (N, 2), computed together."""
        with threads_for(len(xy), CLOUD_MIN):
            found: tuple[NDArray[np.int64], NDArray[np.bool_]] = _locate(
                np.asarray(xy, dtype=np.float64), (self.xmin, self.ymin), self.size, 1 << level)
        return found

    def keys(self, xy: NDArray[np.float64], level: int) -> NDArray[np.int64]:
        """Morton keys of the level-``level`` cells holding ``xy`` (upper edge -> last cell)."""
        cells = 1 << level
        rel = (xy - (self.xmin, self.ymin)) / self.size
        idx = np.clip(np.floor(rel * cells), 0, cells - 1).astype(np.int64)
        return morton_encode(idx[:, 0], idx[:, 1])

    def doubled(self, xy: NDArray[np.float64]) -> tuple[Square, int]:
        """Twice as large a square towards the points outside; returns it and the old quadrant."""
        ox = int(bool((xy[:, 0] < self.xmin).any()))
        oy = int(bool((xy[:, 1] < self.ymin).any()))
        grown = Square(self.xmin - ox * self.size, self.ymin - oy * self.size, 2 * self.size)
        return grown, ox + 2 * oy

    def cell_geometry(self, level: NDArray[np.int64], keys: NDArray[np.int64],
                      ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Centres (K, 2) and edge lengths (K,) of cells given by level and key."""
        ix, iy = morton_decode(keys)
        edge = self.size / np.exp2(level)
        centers = np.column_stack([self.xmin + (ix + 0.5) * edge, self.ymin + (iy + 0.5) * edge])
        return centers, edge
