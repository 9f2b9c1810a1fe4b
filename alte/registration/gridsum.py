"""The voxel grid's hot loops (:mod:`alte.registration.grid`) in numba, value for value.

Every registered cloud is grid-averaged scan by scan and merged into the map's grid, so
these steps run on every point of every bag: the keys' bounds, their packing into one
sortable integer, the cell boundaries after the sort and the per-cell sums. numpy did
each in several passes over temporary arrays (the bounds as strided reductions, now
:func:`alte._kernels.bounds`; the unpacking as an int64 ``divmod``; the sums with
``np.add.reduceat``); here each is one pass. The sums are ``np.add.reduceat``'s to the
last bit (:mod:`alte._kernels`), so the registered clouds, and every pose fitted to them,
do not move.
"""

from __future__ import annotations

import numba
import numpy as np
from numpy.typing import NDArray

from alte._kernels import run_total

__all__ = ["pack", "segment_sums", "unpack"]


@numba.njit(cache=True)
def pack(keys: NDArray[np.int64], low: NDArray[np.int64], span: NDArray[np.int64]
         ) -> NDArray[np.int64]:
    """Per row of ``keys`` (N, 3): its cell code (x, then y, then z, from ``low`` in
    boxes of ``span``) times N plus its row number; the caller checked it fits int64."""
    n = keys.shape[0]
    code = np.empty(n, np.int64)
    for i in range(n):
        cell = ((keys[i, 0] - low[0]) * span[1] + keys[i, 1] - low[1]) * span[2] \
            + keys[i, 2] - low[2]
        code[i] = cell * n + i
    return code


@numba.njit(cache=True)
def unpack(code: NDArray[np.int64]) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """Of sorted :func:`pack` codes: the rows in that order, and where each run of one
    cell starts."""
    n = code.shape[0]
    order, starts = np.empty(n, np.int64), np.empty(n, np.int64)
    runs, last = 0, -1
    for i in range(n):
        cell, order[i] = divmod(code[i], n)
        if i == 0 or cell != last:
            starts[runs] = i
            runs += 1
            last = cell
    return order, starts[:runs]


@numba.njit(cache=True)
def segment_sums(ordered: NDArray[np.float64], starts: NDArray[np.int64]) -> NDArray[np.float64]:
    """``np.add.reduceat(ordered, starts, axis=0)`` for ``ordered`` (N, D) and increasing
    ``starts`` (the first at 0), to the last bit (:func:`alte._kernels.run_total`)."""
    k, n = starts.shape[0], ordered.shape[0]
    out = np.empty((k, ordered.shape[1]))
    for s in range(k):
        end = starts[s + 1] if s + 1 < k else n
        for column in range(ordered.shape[1]):
            out[s, column] = run_total(ordered, column, starts[s], end)
    return out
