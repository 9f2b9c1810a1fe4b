"""Numba kernels of a build that keeps the partition's cells only, in one walk.

An insertion aggregates a frame at the finest level and merges it upwards level by
level (``_cellstats``: ``aggregate_points``, then ``combine`` per level), every cell of
every level. A build whose cells split on their count alone (``n > split_above``)
needs the partition's *tree*, its root and the children of split cells: a few per
cent of all cells once levels are deep (sim_lan_2, ``max_points`` 25: 75 k of 1.49 M
cells, 5 MB of the 97 MB). One walk over the sorted points finds them: a finest cell
closes where the next point's key differs, and with it every coarser cell whose key
differs too; a closing cell merges its (at most 4) children, waiting in a small stack
per level, and writes them out when it splits. The rows are those of the
level-by-level path, bit for bit: the same kernels in the same order (a point alone
in its cells has its own row on each of them, so the walk skips that chain of copies).
A first, top-down pass counts the tree's cells per level (binary searches in the
split cells' ranges of sorted keys), so the walk writes each level in place, once.

The points are sorted by *packed* keys, ``key << shift | index``: one int64 array
moved per radix pass, and the index makes the order stable. The hot loop is one
function: numba passes arrays to a helper as structs of several words, and a call per
cell (or its inlined copy's reference counting) costs more than the cell's arithmetic.
"""

from __future__ import annotations

import itertools

import numba
import numpy as np
from numba.cpython.unsafe.numbers import leading_zeros

from alte.mappers._cellstats import _cell_row, _parent_row, sort_keys

__all__ = ["Sorted", "sort_points", "tree_cells"]

#: Below this many points numba's quicksort of the packed keys beats the radix passes.
_RADIX_MIN = 1 << 14
#: Points sorted by :func:`sort_points`: ``(packed, shift, values)``; ``shift`` 0 when
#: the keys alone are sorted and ``values`` are in their order.
Sorted = tuple[np.ndarray, int, np.ndarray]
#: The walk's output: rows, keys and split flags of every level's cells, level ``l``
#: from ``offsets[l]``, and the next place per level.
Out = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]


@numba.njit(cache=True)
def _sort_packed(keys: np.ndarray, bits: int, shift: int, scratch: np.ndarray,
                 out: np.ndarray) -> np.ndarray:
    """``keys << shift | index`` sorted (LSD radix on the key's ``bits``, digits of at
    most 12 bits); the sorted array is ``out`` or ``scratch``."""
    n = keys.size
    passes = max(1, -(-bits // 12))
    width = -(-max(bits, 1) // passes)
    mask = (1 << width) - 1
    count = np.zeros((passes, (1 << width) + 1), dtype=np.int64)
    for i in range(n):
        out[i] = (keys[i] << shift) | i
        for p in range(passes):
            count[p, ((keys[i] >> (p * width)) & mask) + 1] += 1
    if n < _RADIX_MIN:
        out[:] = np.sort(out)
        return out
    src, dst = out, scratch
    for p in range(passes):
        at = count[p]
        for d in range(1 << width):
            at[d + 1] += at[d]
        for i in range(n):
            d = (src[i] >> (shift + p * width)) & mask
            dst[at[d]] = src[i]
            at[d] += 1
        src, dst = dst, src
    return src


@numba.njit(cache=True, inline="always")
def _coarsest_change(a: int, b: int, depth: int) -> int:
    """Coarsest level at which different finest keys ``a`` and ``b`` name different cells
    (from the highest differing bit: one ``lzcnt``, no branches to mispredict)."""
    return depth - (63 - leading_zeros(np.int64(a ^ b))) // 2  # type: ignore[call-arg]  # numba intrinsic


@numba.njit(cache=True)
def _run_row(points: Sorted, span: tuple[int, int], rows: np.ndarray, s: int) -> None:
    """Row ``s``: the finest cell of the sorted points ``span = (i, j)``, two or more."""
    packed, shift, values = points
    i, j = span
    run, dev = np.empty((j - i, values.shape[1])), np.empty((j - i, values.shape[1]))
    for r in range(i, j):
        p = r if shift == 0 else packed[r] & ((1 << shift) - 1)
        run[r - i, :] = values[p]
    _cell_row(run, (0, j - i), rows, s, dev)


@numba.njit(cache=True)
def _emit(stack: tuple[np.ndarray, np.ndarray], kids: tuple[int, int], level: int,
          flags: tuple[int, float], out: Out) -> None:
    """Write the stack's rows ``kids = (a, b)`` at ``level``'s next places in ``out``,
    each flagged to split when ``level < depth`` and ``n > split_above`` (``flags =
    (depth, split_above)``)."""
    rows, keys = stack
    table, cells, split, at = out
    for k in range(kids[0], kids[1]):
        u = at[level]
        for c in range(rows.shape[1]):
            table[u, c] = rows[k, c]
        cells[u], split[u] = keys[k], level < flags[0] and rows[k, 0] > flags[1]
        at[level] = u + 1


@numba.njit(cache=True)
def _tree_counts(packed: np.ndarray, shift: int, depth: int, split_above: float) -> np.ndarray:
    """Cells per level of the tree (the root, the non-empty children of cells with ``n >
    split_above``), top down: a cell is a range of the sorted keys, its children the
    runs of their next two bits, found by binary search (no pass over every point)."""
    counts = np.zeros(depth + 1, np.int64)
    lo, hi = np.zeros(1, np.int64), np.full(1, packed.size, np.int64)
    counts[0] = packed.size > 0
    for level in range(depth):
        wide = np.flatnonzero(hi - lo > split_above)
        kids_lo, kids_hi, m = np.empty(4 * wide.size, np.int64), np.empty(4 * wide.size,
                                                                          np.int64), 0
        bit = shift + 2 * (depth - level - 1)  # the children's lowest key bit, packed
        for c in wide:
            a, b = lo[c], hi[c]
            while a < b:  # the first key of the next child, by bisection
                first, end, bound = a + 1, b, ((packed[a] >> bit) + 1) << bit
                while first < end:
                    mid = (first + end) >> 1
                    first, end = (mid + 1, end) if packed[mid] < bound else (first, mid)
                kids_lo[m], kids_hi[m], m, a = a, first, m + 1, first
        lo, hi, counts[level + 1] = kids_lo[:m], kids_hi[:m], m
    return counts


@numba.njit(cache=True, error_model="numpy")
def _walk(points: Sorted, depth: int, split_above: float, out: Out) -> None:
    """Write the tree's cells to ``out``, each level's in key order (the children of a
    split cell together, as it closes; the root last). A point alone in its cells from
    level ``top`` down (its neighbours differ there) enters the stack at ``top``: no
    cell of one point splits (``split_above >= 1``), so the chain below holds nothing
    to write."""
    packed, shift, values = points
    n, nv, mask = packed.size, values.shape[1], (1 << shift) - 1
    rows, keys = np.empty((4 * depth + 4, 1 + 3 * nv)), np.empty(4 * depth + 4, np.int64)
    count = np.zeros(depth + 1, np.int64)  # children waiting per level
    i = before = 0  # ``before``: coarsest level where the previous point's cell differs
    while i < n:
        key, j = packed[i] >> shift, i + 1
        while j < n and packed[j] >> shift == key:
            j += 1
        low = _coarsest_change(key, packed[j] >> shift, depth) if j < n else 0
        top = max(before, low) if j - i == 1 else depth
        s, before = 4 * top + count[top], low
        if j - i > 1:
            _run_row(points, (i, j), rows, s)
        else:  # one point: _cell_row's values (v / 1 is v, M2 is 0 * 0)
            rows[s, 0], p = 1.0, i if shift == 0 else packed[i] & mask
            for c in range(nv):
                rows[s, 1 + c], rows[s, 1 + nv + c], rows[s, 1 + 2 * nv + c] = \
                    values[p, c], 0.0, values[p, c]
        keys[s], count[top] = key >> (2 * (depth - top)), count[top] + 1
        for level in range(top - 1, low - 1, -1):
            m, s, kid = count[level + 1], 4 * level + count[level], 4 * level + 4
            _parent_row(rows, (kid, kid + m), rows, s)
            keys[s], count[level], count[level + 1] = keys[kid] >> 2, count[level] + 1, 0
            if rows[s, 0] > split_above:
                _emit((rows, keys), (kid, kid + m), level + 1, (depth, split_above), out)
        i = j
    _emit((rows, keys), (0, 1), 0, (depth, split_above), out)


def sort_points(keys: np.ndarray, values: np.ndarray, bits: int) -> Sorted:
    """Points with finest ``keys`` (below ``2**bits``) and (N, nv) ``values``, stably
    sorted by key: packed with their index when both fit in 63 bits, else by
    ``_cellstats.sort_keys`` with the values put in that order."""
    keys = np.asarray(keys, np.int64)
    values = np.ascontiguousarray(values, np.float64)
    shift = max(1, (keys.size - 1).bit_length())
    if bits + shift > 63:
        sorted_keys, order = sort_keys(keys, bits)
        return sorted_keys, 0, values[order]
    scratch, out = np.empty(keys.size, np.int64), np.empty(keys.size, np.int64)
    return _sort_packed(keys, bits, shift, scratch, out), shift, values


def tree_cells(points: Sorted, depth: int, split_above: float,
               ) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """Per level ``0..depth``: sorted keys, rows ``n, mean.., m2.., max..`` and split
    flags (``n > split_above`` above the finest level) of the root and the children of
    split cells of :func:`sort_points`' points (views of one buffer per array)."""
    assert split_above >= 1.0, "the walk skips cells of one point: they must not split"
    packed, shift, values = points
    offsets = np.zeros(depth + 2, np.int64)
    offsets[1:] = np.cumsum(_tree_counts(packed, shift, depth, float(split_above)))
    out = (np.empty((offsets[-1], 1 + 3 * values.shape[1])), np.empty(offsets[-1], np.int64),
           np.empty(offsets[-1], bool), offsets[:-1].copy())
    if len(packed):
        _walk(points, depth, float(split_above), out)
    assert (out[3] == offsets[1:]).all(), "the walk wrote the cells the count found"
    return [(out[1][a:b], out[0][a:b], out[2][a:b]) for a, b in itertools.pairwise(offsets)]
