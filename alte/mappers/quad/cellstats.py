"""Numba kernels of :class:`alte.mappers.quad.levelstats.LevelStats`: sorting, aggregation, merges.

The sums reproduce numpy's, bit for bit, so that a statistic does not depend on
which kernel computed it: :func:`aggregate_points` sums every run of points as
``np.add.reduceat`` does (first element plus numpy's pairwise sum of the rest) and
:func:`combine` / :func:`merge_cells` keep the formulas (and evaluation order) of the
former numpy code: Chan's parallel mean and ``M2`` update.

A level's *index* finds a cell's storage row from its key without keeping the keys
sorted. Where the level has few enough cells (``4**level``) it is *dense*: int32
``row + 1`` at the key itself (0 = absent), one memory access per lookup, and the
sorted keys of a frame read it in address order; deeper levels use an open-addressing
table of ``key, row`` pairs (int64, key -1 = empty), key and row in one cache line.
"""

from __future__ import annotations

import numba
import numpy as np
from numpy.typing import NDArray

from alte._kernels import run_total

__all__ = ["Index", "aggregate_points", "combine", "fill_index", "merge_cells", "sort_keys"]

#: A level's row index: dense (int32 ``row + 1`` per key) or hashed (int64 ``key, row`` pairs).
Index = NDArray[np.int32] | NDArray[np.int64]

_GOLDEN = np.uint64(0x9E3779B97F4A7C15)
#: Below this many keys numba's merge sort beats the radix passes' fixed cost.
_RADIX_MIN = 1 << 14


@numba.njit(cache=True)
def sort_keys(keys: NDArray[np.int64], bits: int) -> tuple[NDArray[np.int64], NDArray[np.intp]]:
    """Stably sorted non-negative int64 ``keys`` below ``2**bits`` and their order (LSD
    radix sort of key and index together, digits of at most 12 bits counted in one
    pass; numba's merge sort for short arrays)."""
    n = keys.size
    if n < _RADIX_MIN:
        order = np.argsort(keys, kind="mergesort")
        return keys[order], order
    passes = max(1, -(-bits // 12))
    width = -(-max(bits, 1) // passes)
    mask = (1 << width) - 1
    count = np.zeros((passes, (1 << width) + 1), dtype=np.int64)
    for i in range(n):
        for p in range(passes):
            count[p, ((keys[i] >> (p * width)) & mask) + 1] += 1
    src_k, src_o = keys.copy(), np.arange(n)
    dst_k, dst_o = np.empty(n, dtype=np.int64), np.empty(n, dtype=np.int64)
    for p in range(passes):
        at = count[p]
        for d in range(1 << width):
            at[d + 1] += at[d]
        for i in range(n):
            d = (src_k[i] >> (p * width)) & mask
            dst_k[at[d]], dst_o[at[d]] = src_k[i], src_o[i]
            at[d] += 1
        src_k, dst_k, src_o, dst_o = dst_k, src_k, dst_o, src_o
    return src_k, src_o


@numba.njit(cache=True)
def _run_starts(keys: NDArray[np.int64], shift: int) -> NDArray[np.int64]:
    """Start index of every run of equal ``keys >> shift`` in sorted ``keys``, then ``n``."""
    n = keys.size
    runs = 0
    for i in range(n):
        runs += i == 0 or (keys[i] >> shift) != (keys[i - 1] >> shift)
    starts = np.empty(runs + 1, dtype=np.int64)
    s = 0
    for i in range(n):
        if i == 0 or (keys[i] >> shift) != (keys[i - 1] >> shift):
            starts[s] = i
            s += 1
    starts[runs] = n
    return starts


@numba.njit(cache=True)
def _point_row(values: NDArray[np.float64], a: int, out: NDArray[np.float64], s: int) -> None:
    """Row ``s`` of ``out`` for the one point ``values[a]``: :func:`_cell_row`'s formulas
    with ``n = 1`` (``v / 1`` is ``v``, ``M2`` is ``0 * 0``), the usual finest cell."""
    nv = values.shape[1]
    out[s, 0] = 1.0
    for j in range(nv):
        mean = values[a, j] / 1.0
        d = values[a, j] - mean
        out[s, 1 + j], out[s, 1 + nv + j] = mean, d * d
        out[s, 1 + 2 * nv + j] = values[a, j]


@numba.njit(cache=True)
def _cell_row(values: NDArray[np.float64], run: tuple[int, int], out: NDArray[np.float64], s: int,
              dev: NDArray[np.float64]) -> None:
    """Row ``s`` of ``out``: ``n, mean.., m2.., max..`` of the points ``values[a:b]``,
    ``run = (a, b)`` (``np.add.reduceat``'s sums; ``dev``: scratch of the values' shape).
    A plain function: numba's ``inline="always"`` adds reference counting of the arrays
    per call, which costs more than a one-point row (callers test ``b - a == 1`` first
    and call :func:`_point_row`, which LLVM inlines)."""
    a, b = run
    if b - a == 1:
        _point_row(values, a, out, s)
        return
    nv = values.shape[1]
    out[s, 0] = count = np.float64(b - a)
    for j in range(nv):
        mean = run_total(values, j, a, b) / count
        top = values[a, j]
        for i in range(a, b):
            d = values[i, j] - mean
            dev[i, j] = d * d
            top = max(top, values[i, j])
        out[s, 1 + j], out[s, 1 + 2 * nv + j] = mean, top
        out[s, 1 + nv + j] = run_total(dev, j, a, b)


@numba.njit(cache=True)
def aggregate_points(keys: NDArray[np.int64], values: NDArray[np.float64],
                     ) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
    """Cells of sorted point ``keys`` and their rows ``n, mean.., m2.., max..``."""
    starts = _run_starts(keys, 0)
    out = np.empty((starts.size - 1, 1 + 3 * values.shape[1]))
    cells = np.empty(starts.size - 1, dtype=np.int64)
    dev = np.empty(values.shape)
    for s in range(starts.size - 1):
        cells[s] = keys[starts[s]]
        if starts[s + 1] - starts[s] == 1:
            _point_row(values, starts[s], out, s)
        else:
            _cell_row(values, (starts[s], starts[s + 1]), out, s, dev)
    return cells, out


@numba.njit(cache=True, error_model="numpy")
def _parent_row(rows: NDArray[np.float64], run: tuple[int, int], out: NDArray[np.float64],
                s: int) -> None:
    """Row ``s`` of ``out``: Chan's merge of the (at most 4) child rows ``rows[a:b]``,
    ``run = (a, b)``, each sum in ``np.add.reduceat``'s order on short runs (``x[0] +
    (x[1] + ... + x[m-1])``), in registers (no scratch; counts are >= 1, never 0)."""
    a, b = run
    nv = (rows.shape[1] - 1) // 3
    count = rows[a, 0]
    if b - a > 1:
        rest = rows[a + 1, 0]
        for i in range(a + 2, b):
            rest += rows[i, 0]
        count = count + rest
    out[s, 0] = count
    for j in range(1, 1 + nv):
        total, top = rows[a, 0] * rows[a, j], rows[a, 2 * nv + j]
        if b - a > 1:
            rest = rows[a + 1, 0] * rows[a + 1, j]
            for i in range(a + 2, b):
                rest += rows[i, 0] * rows[i, j]
            total = total + rest
        mean = total / count
        dev = rows[a, j] - mean
        total = rows[a, nv + j] + rows[a, 0] * dev * dev
        if b - a > 1:
            dev = rows[a + 1, j] - mean
            rest = rows[a + 1, nv + j] + rows[a + 1, 0] * dev * dev
            for i in range(a + 2, b):
                dev = rows[i, j] - mean
                rest += rows[i, nv + j] + rows[i, 0] * dev * dev
            total = total + rest
        for i in range(a + 1, b):
            top = max(top, rows[i, 2 * nv + j])
        out[s, j], out[s, nv + j], out[s, 2 * nv + j] = mean, total, top


@numba.njit(cache=True)
def combine(keys: NDArray[np.int64], rows: NDArray[np.float64], nv: int,
            ) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
    """Parent cells (key >> 2) of sorted child ``keys`` with Chan's merge of their rows."""
    starts = _run_starts(keys, 2)
    out = np.empty((starts.size - 1, rows.shape[1]))
    parents = np.empty(starts.size - 1, dtype=np.int64)
    for s in range(starts.size - 1):
        parents[s] = keys[starts[s]] >> 2
        _parent_row(rows, (starts[s], starts[s + 1]), out, s)
    return parents, out


@numba.njit(cache=True, inline="always")
def _locate(index: Index, key: int, dense: bool) -> int:
    """Position of ``key`` in ``index``: the key itself (dense), else the slot holding it
    or the empty slot where it belongs (hashed: pairs ``key, row``; key -1 = empty)."""
    if dense:
        return int(key)
    mask = np.int64(index.size // 2 - 1)
    j = np.int64((np.uint64(key) * _GOLDEN) >> np.uint64(32)) & mask
    while index[2 * j] != -1 and index[2 * j] != key:
        j = (j + 1) & mask
    return int(j)


@numba.njit(cache=True, inline="always")
def _row(index: Index, j: int, key: int, dense: bool) -> int:
    """Row stored at position ``j`` for ``key``; -1 when the key is absent."""
    if dense:
        return int(index[j]) - 1
    return int(index[2 * j + 1]) if index[2 * j] == key else -1


@numba.njit(cache=True, inline="always")
def _set(index: Index, j: int, key: int, row: int, dense: bool) -> None:
    if dense:
        index[j] = row + 1
    else:
        index[2 * j], index[2 * j + 1] = key, row


@numba.njit(cache=True)
def fill_index(index: Index, keys: NDArray[np.int64], n: int, dense: bool) -> None:
    """Point ``index`` at the rows of the first ``n`` keys (an empty index, or one already
    holding exactly these keys at other rows: the rows are rewritten in place)."""
    for row in range(n):
        _set(index, _locate(index, keys[row], dense), keys[row], row, dense)


@numba.njit(cache=True)
def merge_cells(store: tuple[NDArray[np.int64], NDArray[np.float64], NDArray[np.bool_], Index],
                n: int, cells: tuple[NDArray[np.int64], NDArray[np.float64]], nv: int,
                dense: bool) -> tuple[NDArray[np.int64], int]:
    """Merge ``cells`` = (keys, rows) into a level's ``store`` = (keys, rows, split, index)
    holding ``n`` cells, capacity reserved; returns their rows and the new n.

    Known cells get Chan's pairwise update in place; new ones are appended."""
    skeys, srows, split, index = store
    keys, agg = cells
    touched = np.empty(keys.size, dtype=np.int64)
    for i in range(keys.size):
        j = _locate(index, keys[i], dense)
        row = _row(index, j, keys[i], dense)
        if row < 0:
            skeys[n], split[n] = keys[i], False
            for c in range(agg.shape[1]):
                srows[n, c] = agg[i, c]
            _set(index, j, keys[i], n, dense)
            touched[i] = n
            n += 1
            continue
        touched[i] = row
        na, nb = srows[row, 0], agg[i, 0]
        total = na + nb
        for v in range(nv):
            delta = agg[i, 1 + v] - srows[row, 1 + v]
            srows[row, 1 + v] = srows[row, 1 + v] + delta * (nb / total)
            srows[row, 1 + nv + v] = (srows[row, 1 + nv + v] + agg[i, 1 + nv + v]
                                      + delta * delta * (na * nb / total))
            srows[row, 1 + 2 * nv + v] = max(srows[row, 1 + 2 * nv + v], agg[i, 1 + 2 * nv + v])
        srows[row, 0] = total
    return touched, n
