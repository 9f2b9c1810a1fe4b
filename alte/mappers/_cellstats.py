"""Numba kernels of :class:`alte.mappers.levelstats.LevelStats`: sorting, aggregation, merges.

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

__all__ = ["aggregate_points", "combine", "fill_index", "merge_cells", "stable_order"]

_GOLDEN = np.uint64(0x9E3779B97F4A7C15)
#: Below this many keys numba's merge sort beats the radix passes' fixed cost.
_RADIX_MIN = 1 << 14


@numba.njit(cache=True)
def stable_order(keys: np.ndarray, bits: int) -> np.ndarray:
    """Stable argsort of non-negative int64 ``keys`` below ``2**bits`` (LSD radix, 8 bits
    a pass; a merge sort for short arrays)."""
    n = keys.size
    if n < _RADIX_MIN:
        return np.argsort(keys, kind="mergesort")
    order = np.arange(n)
    spare = np.empty(n, dtype=np.int64)
    count = np.empty(257, dtype=np.int64)
    for shift in range(0, max(bits, 1), 8):
        count[:] = 0
        for i in range(n):
            count[((keys[i] >> shift) & 255) + 1] += 1
        for d in range(256):
            count[d + 1] += count[d]
        for i in range(n):
            d = (keys[order[i]] >> shift) & 255
            spare[count[d]] = order[i]
            count[d] += 1
        order, spare = spare, order
    return order


@numba.njit(cache=True)
def _pairwise(x: np.ndarray, j: int, a: int, n: int) -> float:
    """numpy's pairwise sum of ``x[a:a + n, j]`` (8 accumulators, blocks of 128)."""
    if n < 8:
        res = -0.0
        for i in range(a, a + n):
            res += x[i, j]
        return res
    if n <= 128:
        r = x[a:a + 8, j].copy()
        m = n - n % 8
        for i in range(8, m, 8):
            for q in range(8):
                r[q] += x[a + i + q, j]
        res = ((r[0] + r[1]) + (r[2] + r[3])) + ((r[4] + r[5]) + (r[6] + r[7]))
        for i in range(m, n):
            res += x[a + i, j]
        return res
    half = n // 2
    half -= half % 8
    return _pairwise(x, j, a, half) + _pairwise(x, j, a + half, n - half)


@numba.njit(cache=True, inline="always")
def _run_total(x: np.ndarray, j: int, a: int, b: int) -> float:
    """``np.add.reduceat`` of the run ``x[a:b, j]``."""
    return x[a, j] + _pairwise(x, j, a + 1, b - a - 1) if b - a > 1 else x[a, j]


@numba.njit(cache=True)
def aggregate_points(keys: np.ndarray, values: np.ndarray):
    """Cells of sorted point ``keys`` and their rows ``n, mean.., m2.., max..``."""
    n, nv = values.shape
    starts = np.flatnonzero(np.diff(keys)) + 1
    starts = np.concatenate((np.zeros(min(n, 1), np.int64), starts))
    out = np.empty((starts.size, 1 + 3 * nv))
    dev = np.empty((n, nv))
    for s in range(starts.size):
        a, b = starts[s], starts[s + 1] if s + 1 < starts.size else n
        out[s, 0] = count = np.float64(b - a)
        for j in range(nv):
            mean = _run_total(values, j, a, b) / count
            top = values[a, j]
            for i in range(a, b):
                d = values[i, j] - mean
                dev[i, j] = d * d
                top = max(top, values[i, j])
            out[s, 1 + j], out[s, 1 + 2 * nv + j] = mean, top
            out[s, 1 + nv + j] = _run_total(dev, j, a, b)
    return keys[starts], out


@numba.njit(cache=True, inline="always")
def _run_sum(x: np.ndarray, a: int, b: int) -> float:
    """``x[a] + (x[a+1] + ... + x[b-1])``: the order of ``np.add.reduceat`` on short runs."""
    if b - a == 1:
        return x[a]
    rest = x[a + 1]
    for i in range(a + 2, b):
        rest += x[i]
    return x[a] + rest


@numba.njit(cache=True)
def combine(keys: np.ndarray, rows: np.ndarray, nv: int):
    """Parent cells (key >> 2) of sorted child ``keys`` with Chan's merge of their rows."""
    parents = keys >> 2
    starts = np.flatnonzero(np.diff(parents)) + 1
    starts = np.concatenate((np.zeros(min(keys.size, 1), np.int64), starts))
    out = np.empty((starts.size, rows.shape[1]))
    term = np.empty(4)
    col = np.empty(4)
    for s in range(starts.size):
        a, b = starts[s], starts[s + 1] if s + 1 < starts.size else keys.size
        for i in range(a, b):
            col[i - a] = rows[i, 0]
        out[s, 0] = count = _run_sum(col, 0, b - a)
        for j in range(nv):
            for i in range(a, b):
                term[i - a] = rows[i, 0] * rows[i, 1 + j]
            out[s, 1 + j] = mean = _run_sum(term, 0, b - a) / count
            top = rows[a, 1 + 2 * nv + j]
            for i in range(a, b):
                dev = rows[i, 1 + j] - mean
                term[i - a] = rows[i, 1 + nv + j] + rows[i, 0] * dev * dev
                top = max(top, rows[i, 1 + 2 * nv + j])
            out[s, 1 + nv + j] = _run_sum(term, 0, b - a)
            out[s, 1 + 2 * nv + j] = top
    return parents[starts], out


@numba.njit(cache=True, inline="always")
def _locate(index: np.ndarray, key: int, dense: bool) -> int:
    """Position of ``key`` in ``index``: the key itself (dense), else the slot holding it
    or the empty slot where it belongs (hashed: pairs ``key, row``; key -1 = empty)."""
    if dense:
        return np.int64(key)
    mask = np.int64(index.size // 2 - 1)
    j = np.int64((np.uint64(key) * _GOLDEN) >> np.uint64(32)) & mask
    while index[2 * j] != -1 and index[2 * j] != key:
        j = (j + 1) & mask
    return j


@numba.njit(cache=True, inline="always")
def _row(index: np.ndarray, j: int, key: int, dense: bool) -> int:
    """Row stored at position ``j`` for ``key``; -1 when the key is absent."""
    if dense:
        return int(index[j]) - 1
    return int(index[2 * j + 1]) if index[2 * j] == key else -1


@numba.njit(cache=True, inline="always")
def _set(index: np.ndarray, j: int, key: int, row: int, dense: bool) -> None:
    if dense:
        index[j] = row + 1
    else:
        index[2 * j], index[2 * j + 1] = key, row


@numba.njit(cache=True)
def fill_index(index: np.ndarray, keys: np.ndarray, n: int, dense: bool) -> None:
    """Point ``index`` at the rows of the first ``n`` keys (an empty index, or one already
    holding exactly these keys at other rows: the rows are rewritten in place)."""
    for row in range(n):
        _set(index, _locate(index, keys[row], dense), keys[row], row, dense)


@numba.njit(cache=True)
def merge_cells(store, n: int, cells, nv: int, dense: bool):
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
            srows[n] = agg[i]
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
