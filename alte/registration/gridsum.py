"""The voxel grid's hot loops (:mod:`alte.registration.grid`) in numba, value for value.

Every registered cloud is grid-averaged scan by scan and merged into the map's grid, so
these steps run on every point of every bag: the keys' bounds, their packing into one
sortable integer, the cell boundaries after the sort and the per-cell sums. numpy did
each in several passes over temporary arrays (the bounds as strided reductions, now
:func:`alte._kernels.bounds`; the unpacking as an int64 ``divmod``; the sums with
``np.add.reduceat`` of the rows gathered in sorted order); here each is one pass, the sums
read through the order. The sums are ``np.add.reduceat``'s to the last bit
(:mod:`alte._kernels`), so the registered clouds, and every pose fitted to them, do not
move.
"""

from __future__ import annotations

import numba
import numpy as np
from numpy.typing import NDArray

from alte._kernels import run_total

__all__ = ["gathered_sums", "pack", "unpack"]


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
def gathered_sums(sums: NDArray[np.float64], counts: NDArray[np.float64],
                  order: NDArray[np.int64], starts: NDArray[np.int64],
                  ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``np.add.reduceat`` of ``sums[order]`` (N, D) and ``counts[order]`` (N,) at the
    increasing ``starts`` (the first at 0), without gathering them first: a one-row cell
    is copied, a longer run gathered into a scratch block and summed there by the same
    :func:`~alte._kernels.run_total`, so the bits are the same."""
    k, n, d = starts.shape[0], order.shape[0], sums.shape[1]
    longest = 1
    for s in range(k):
        longest = max(longest, (starts[s + 1] if s + 1 < k else n) - starts[s])
    out, total = np.empty((k, d)), np.empty(k)
    block, weights = np.empty((longest, d)), np.empty((longest, 1))
    for s in range(k):
        a = starts[s]
        size = (starts[s + 1] if s + 1 < k else n) - a
        if size == 1:
            for column in range(d):
                out[s, column] = sums[order[a], column]
            total[s] = counts[order[a]]
            continue
        for i in range(size):
            row = order[a + i]
            for column in range(d):
                block[i, column] = sums[row, column]
            weights[i, 0] = counts[row]
        for column in range(d):
            out[s, column] = run_total(block, column, 0, size)
        total[s] = run_total(weights, 0, 0, size)
    return out, total
