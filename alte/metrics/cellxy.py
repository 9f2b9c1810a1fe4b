"""Which 2D cell holds each x/y point: a lattice lookup per cell size, compiled.

The 2D metrics ask it for every probe of a 0.2 m grid over the control volume (hundreds
of thousands of points) and every map; the landing raster and the real ground checks
ask it too. Within one size group the cells of a tree lie on a lattice, so a point's
lattice index (floor of its offset over the cell size) names the only cell that can
hold it, found by a binary search over the group's sorted keys; a point on a cell edge
is also tried against the cells below it on that axis. Containment is then checked
exactly (edges included, 1e-9 m of slack). The keys, their order and the search are
numpy's (:func:`numpy.argsort`, :func:`numpy.searchsorted`); the per-point loop runs
in numba, so no temporary arrays are made per group and shift.
"""

from __future__ import annotations

import numba
import numpy as np
from numpy.typing import NDArray

from alte.mappers._rows import row_groups

__all__ = ["cell_at_xy", "lattice_keys", "size_groups"]

#: Lattice indices are clipped to +-2**30 before they are packed into one int64 key.
_SHIFT = 1 << 30
#: Slack of the containment check (m).
_SLACK = 1e-9


def size_groups(half: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.intp]]:
    """Distinct half sizes and, per cell, the index of its group (trees have few sizes)."""
    return row_groups(np.round(half, 9))


def lattice_keys(ij: NDArray[np.int64]) -> NDArray[np.int64]:
    """One int64 per (i, j) lattice index pair (each shifted into 32 bits)."""
    shifted = np.clip(ij, -_SHIFT, _SHIFT - 1) + _SHIFT
    return np.asarray((shifted[:, 0] << 32) | shifted[:, 1], dtype=np.int64)


@numba.njit(cache=True, inline="always")
def _key(i: int, j: int) -> int:
    """:func:`lattice_keys` of one pair."""
    i = min(max(i, -_SHIFT), _SHIFT - 1) + _SHIFT
    j = min(max(j, -_SHIFT), _SHIFT - 1) + _SHIFT
    return (i << 32) | j


@numba.njit(cache=True)
def _lookup(  # noqa: PLR0917 - a numba kernel's arrays
    xy: NDArray[np.float64], centers: NDArray[np.float64], cells: NDArray[np.int64],
    sorted_keys: NDArray[np.int64], frame: NDArray[np.float64], found: NDArray[np.int64],
) -> None:
    """Give each point of ``xy`` not ``found`` yet the cell of this group holding it.

    ``cells``: the group's cell rows in key order; ``frame``: half size, origin and step
    (x, y each). Shifts are tried in the order (0, 0), (1, 0), (0, 1), (1, 1).
    """
    n = sorted_keys.shape[0]
    h0, h1, o0, o1, s0, s1 = frame[0], frame[1], frame[2], frame[3], frame[4], frame[5]
    for p in range(xy.shape[0]):
        x, y = xy[p, 0], xy[p, 1]
        if found[p] >= 0 or not (np.isfinite(x) and np.isfinite(y)):
            continue
        r0, r1 = (x - o0) / s0, (y - o1) / s1
        f0, f1 = np.floor(r0), np.floor(r1)
        i0 = int(min(max(f0, -2.0 * _SHIFT), 2.0 * _SHIFT))
        i1 = int(min(max(f1, -2.0 * _SHIFT), 2.0 * _SHIFT))
        for shift in range(4):
            d0, d1 = shift & 1, shift >> 1
            if (d0 == 1 and f0 != r0) or (d1 == 1 and f1 != r1):
                continue
            query = _key(i0 - d0, i1 - d1)
            pos = min(np.searchsorted(sorted_keys, query), n - 1)
            if sorted_keys[pos] != query:
                continue
            c = cells[pos]
            if abs(x - centers[c, 0]) <= h0 + _SLACK and abs(y - centers[c, 1]) <= h1 + _SLACK:
                found[p] = c
                break


def cell_at_xy(xy: NDArray[np.float64], centers: NDArray[np.float64], sizes: NDArray[np.float64],
               ) -> NDArray[np.int64]:
    """Index of the 2D cell whose x/y rectangle holds each point, -1 where none does
    (module docstring); size groups are tried in :func:`size_groups`' order."""
    xy = np.ascontiguousarray(xy, dtype=np.float64)
    found = np.full(len(xy), -1, dtype=np.int64)
    if len(xy) == 0 or len(centers) == 0:
        return found
    centers = np.ascontiguousarray(centers, dtype=np.float64)
    half = np.asarray(sizes, dtype=np.float64)[:, :2] / 2.0
    groups, inverse = size_groups(half)
    for g, h in enumerate(groups):
        sel = np.flatnonzero(inverse.reshape(-1) == g)
        step = np.maximum(2.0 * h, 1e-12)
        origin = centers[sel[0], :2] - h
        keys = lattice_keys(np.rint((centers[sel, :2] - h - origin) / step).astype(np.int64))
        order = np.argsort(keys)
        frame = np.concatenate([h, origin, step]).astype(np.float64)
        _lookup(xy, centers, sel[order].astype(np.int64), keys[order], frame, found)
    return found
