"""numba kernels several stages share: one-pass bounds, and numpy's float64 sums to the
last bit (``np.add.reduce`` and ``np.add.reduceat``).

numpy's axis-0 reductions of an (N, 3) array are several times slower than one pass
(:func:`bounds`). numpy adds a run of values by pairwise summation
(``numpy/_core/src/umath/loops_utils.h.src``): a plain loop from -0.0 below 8 values,
eight running sums over blocks of up to 128, halves beyond; ``np.add.reduceat`` takes a
run's first value plus that sum of the rest. Kernels that replace numpy code with a
one-pass loop (the Quadtree's cell statistics, the voxel grid of every registered cloud)
add in this order, so that no statistic, cloud or pose depends on which code computed it.
"""

from __future__ import annotations

from typing import Any

import numba
import numpy as np
from numpy.typing import NDArray

__all__ = ["bounds", "pairwise", "pairwise_block", "run_total"]


@numba.njit(cache=True)
def bounds(values: NDArray[Any]) -> tuple[NDArray[Any], NDArray[Any]]:
    """Per column of ``values`` (N >= 1, D), its least and greatest value, in one pass
    (of the values' own type: float points or integer cell keys)."""
    low, high = values[0].copy(), values[0].copy()
    for i in range(1, values.shape[0]):
        for a in range(values.shape[1]):
            v = values[i, a]
            if v < low[a]:
                low[a] = v
            elif v > high[a]:
                high[a] = v
    return low, high


@numba.njit(cache=True, inline="always")
def pairwise_block(x: NDArray[np.float64], j: int, a: int, n: int) -> float:
    """numpy's pairwise sum of ``x[a:a + n, j]`` for ``n <= 128``: a plain loop below 8,
    else 8 accumulators (scalars: no scratch array per call)."""
    res = -0.0
    if n < 8:
        for i in range(a, a + n):
            res += x[i, j]
        return float(res)
    r0, r1, r2, r3 = x[a, j], x[a + 1, j], x[a + 2, j], x[a + 3, j]
    r4, r5, r6, r7 = x[a + 4, j], x[a + 5, j], x[a + 6, j], x[a + 7, j]
    m = n - n % 8
    for i in range(a + 8, a + m, 8):
        r0, r1, r2, r3 = r0 + x[i, j], r1 + x[i + 1, j], r2 + x[i + 2, j], r3 + x[i + 3, j]
        r4, r5, r6, r7 = r4 + x[i + 4, j], r5 + x[i + 5, j], r6 + x[i + 6, j], r7 + x[i + 7, j]
    res = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
    for i in range(a + m, a + n):
        res += x[i, j]
    return float(res)


@numba.njit(cache=True)
def pairwise(x: NDArray[np.float64], j: int, a: int, n: int) -> float:
    """numpy's pairwise sum of ``x[a:a + n, j]`` (8 accumulators, blocks of 128)."""
    if n <= 128:
        return pairwise_block(x, j, a, n)
    half = n // 2
    half -= half % 8
    return pairwise(x, j, a, half) + pairwise(x, j, a + half, n - half)


@numba.njit(cache=True, inline="always")
def run_total(x: NDArray[np.float64], j: int, a: int, b: int) -> float:
    """``np.add.reduceat`` of the run ``x[a:b, j]``."""
    if b - a <= 129:  # the usual short run: no call
        return float(x[a, j] + pairwise_block(x, j, a + 1, b - a - 1) if b - a > 1 else x[a, j])
    return float(x[a, j] + pairwise(x, j, a + 1, b - a - 1))
