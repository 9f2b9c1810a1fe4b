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

The cells of level 3 hold disjoint runs of the sorted points, so a whole cloud is
walked on every thread, one contiguous group of those cells each, up to level 3; their
rows then go through the same walk for levels 3..0. Each cell's places per level come
from the counting pass, so the output is the single walk's, bit for bit.

The points come sorted by :mod:`~alte.mappers.quad.radix` (packed keys). The hot loop is one
function: numba passes arrays to a helper as structs of several words, and a call per
cell (or its inlined copy's reference counting) costs more than the cell's arithmetic.
"""

from __future__ import annotations

import itertools

import numba
import numpy as np
from numba.cpython.unsafe.numbers import leading_zeros
from numpy.typing import NDArray

from alte._numba import CLOUD_MIN
from alte.mappers.quad.cellstats import _cell_row, _parent_row, _run_starts
from alte.mappers.quad.radix import Sorted, sort_points

__all__ = ["Sorted", "sort_points", "tree_cells"]

#: From ``CLOUD_MIN`` points on, the cells of this level are walked side by side, one
#: contiguous group of them per thread, and the levels above from their rows.
_SPLIT_LEVEL = 3
#: The walk's output: rows, keys and split flags of every level's cells, level ``l``
#: from ``offsets[l]``, and the next place per level.
Out = tuple[NDArray[np.float64], NDArray[np.int64], NDArray[np.bool_], NDArray[np.int64]]


@numba.njit(cache=True, inline="always")
def _coarsest_change(a: int, b: int, depth: int) -> int:
    """Coarsest level at which different finest keys ``a`` and ``b`` name different cells
    (from the highest differing bit: one ``lzcnt``, no branches to mispredict)."""
    return depth - (63 - leading_zeros(np.int64(a ^ b))) // 2  # type: ignore[call-arg]  # numba intrinsic


@numba.njit(cache=True)
def _run_row(points: Sorted, span: tuple[int, int], rows: NDArray[np.float64], s: int,
             scratch: tuple[NDArray[np.float64], NDArray[np.float64]]) -> None:
    """Row ``s``: the finest cell of the sorted points ``span = (i, j)``, two or more
    (``scratch``: two arrays of at least ``j - i`` rows)."""
    packed, shift, values = points
    i, j = span
    run, dev = scratch
    for r in range(i, j):
        p = r if shift == 0 else packed[r] & ((1 << shift) - 1)
        for c in range(values.shape[1]):
            run[r - i, c] = values[p, c]
    _cell_row(run, (int(np.int64(0)), j - i), rows, s, dev)  # cellstats' signature, not a Literal 0


@numba.njit(cache=True)
def _emit(stack: tuple[NDArray[np.float64], NDArray[np.int64]], kids: tuple[int, int], level: int,
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
def _tree_counts(packed: NDArray[np.int64], shift: int, depth: int,
                 split_above: float) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """Cells per level of the tree (the root, the non-empty children of cells with ``n >
    split_above``) and each cell's first sorted point, levels one after the other, top
    down: a cell is a range of the sorted keys, its children the runs of their next two
    bits, found by binary search (no pass over every point)."""
    counts = np.zeros(depth + 1, np.int64)
    lo, hi = np.zeros(1, np.int64), np.full(1, packed.size, np.int64)
    counts[0] = packed.size > 0
    firsts = [lo[:counts[0]].copy()]
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
        firsts.append(lo.copy())
    joined, at = np.empty(counts.sum(), np.int64), 0
    for level_firsts in firsts:
        for f in range(level_firsts.size):  # element by element: no shape check to compile
            joined[at + f] = level_firsts[f]
        at += level_firsts.size
    return counts, joined


@numba.njit(cache=True, error_model="numpy")
def _walk(points: Sorted, span: tuple[int, int, int], flags: tuple[int, float], out: Out,
          root: tuple[NDArray[np.float64], NDArray[np.int64], int]) -> None:
    """Write the cells below level ``floor`` of the points ``i..end`` (``span = (i, end,
    floor)``: those of one cell at ``floor``; all of them for floor 0) to ``out``, each
    level's in key order (the children of a split cell together, as it closes), and put
    that cell's row and key in ``root = (rows, keys, t)`` at ``t``. A point alone in its
    cells from level ``top`` down (its neighbours differ there) enters the stack at
    ``top``: no cell of one point splits (``split_above >= 1``), so the chain below
    holds nothing to write."""
    packed, shift, values = points
    depth, split_above = flags
    (i, end, floor), nv, mask = span, values.shape[1], (1 << shift) - 1
    rows, keys = np.empty((4 * depth + 4, 1 + 3 * nv)), np.empty(4 * depth + 4, np.int64)
    scratch = (np.empty((64, nv)), np.empty((64, nv)))  # grown for a longer run
    count = np.zeros(depth + 1, np.int64)  # children waiting per level
    before = floor  # coarsest level where the previous point's cell differs
    while i < end:
        key, j = packed[i] >> shift, i + 1
        while j < end and packed[j] >> shift == key:
            j += 1
        low = max(floor, _coarsest_change(key, packed[j] >> shift, depth)) if j < end else floor
        top = max(before, low) if j - i == 1 else depth
        s, before = 4 * top + count[top], low
        if j - i > scratch[0].shape[0]:
            scratch = (np.empty((2 * (j - i), nv)), np.empty((2 * (j - i), nv)))
        if j - i > 1:
            _run_row(points, (i, j), rows, s, scratch)
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
                _emit((rows, keys), (kid, kid + m), level + 1, flags, out)
        i = j
    for c in range(rows.shape[1]):
        root[0][root[2], c] = rows[4 * floor, c]
    root[1][root[2]] = keys[4 * floor]


@numba.njit(cache=True, error_model="numpy")
def _walk_top(cells: tuple[NDArray[np.float64], NDArray[np.int64]], floor: int,
              flags: tuple[int, float], out: Out) -> None:
    """The levels ``0..floor`` from the rows and keys of the non-empty cells at
    ``floor`` in key order, merged, split and written as :func:`_walk` does (a cell of
    one point enters where its neighbours differ, as that point would have)."""
    cell_rows, cell_keys = cells
    rows = np.empty((4 * floor + 4, cell_rows.shape[1]))
    keys = np.empty(4 * floor + 4, np.int64)
    count = np.zeros(floor + 1, np.int64)
    before = 0
    for t in range(cell_keys.size):
        key = cell_keys[t]
        low = _coarsest_change(key, cell_keys[t + 1], floor) if t + 1 < cell_keys.size else 0
        top = max(before, low) if cell_rows[t, 0] == 1.0 else floor
        s, before = 4 * top + count[top], low
        for c in range(rows.shape[1]):  # element by element: no shape check to compile
            rows[s, c] = cell_rows[t, c]
        keys[s], count[top] = key >> (2 * (floor - top)), count[top] + 1
        for level in range(top - 1, low - 1, -1):
            m, s, kid = count[level + 1], 4 * level + count[level], 4 * level + 4
            _parent_row(rows, (kid, kid + m), rows, s)
            keys[s], count[level], count[level + 1] = keys[kid] >> 2, count[level] + 1, 0
            if rows[s, 0] > flags[1]:
                _emit((rows, keys), (kid, kid + m), level + 1, flags, out)
    _emit((rows, keys), (0, 1), 0, flags, out)


@numba.njit(cache=True, parallel=True)
def _walk_groups(points: Sorted, cuts: tuple[NDArray[np.int64], NDArray[np.int64], int],
                 flags: tuple[int, float], out: Out,
                 cells: tuple[NDArray[np.float64], NDArray[np.int64]]) -> None:
    """:func:`_walk` of every cell at level ``floor`` (``cuts = (spans, groups, floor)``;
    ``spans``: the cells' first points, then ``n``), group ``g`` of them (``groups[g]..
    groups[g + 1]``) on a thread of its own; ``out[3]`` holds each cell's next places per
    level (a row per cell)."""
    spans, groups, floor = cuts
    table, keys, split, places = out
    for g in numba.prange(groups.size - 1):
        for t in range(groups[g], groups[g + 1]):
            _walk(points, (spans[t], spans[t + 1], floor), flags,
                  (table, keys, split, places[t]), (cells[0], cells[1], t))


@numba.njit(cache=True)
def _output(cells: int, width: int,
            ) -> tuple[NDArray[np.float64], NDArray[np.int64], NDArray[np.bool_]]:
    """The walk's rows, keys and flags, allocated by numba: numpy asks the kernel for huge
    pages from 4 MiB on, whose first touch (zeroing, compaction) costs more than a walk."""
    return np.empty((cells, width)), np.empty(cells, np.int64), np.empty(cells, np.bool_)


def _places(spans: NDArray[np.int64], firsts: NDArray[np.int64], offsets: NDArray[np.int64],
            floor: int) -> NDArray[np.int64]:
    """Each floor cell's first place per level below ``floor`` in the output: the
    level's offset plus the tree cells of the floor cells before it (by first point)."""
    places = np.zeros((spans.size - 1, offsets.size - 1), np.int64)
    for level in range(floor + 1, offsets.size - 1):
        owner = np.searchsorted(spans, firsts[offsets[level]:offsets[level + 1]], "right") - 1
        held = np.bincount(owner, minlength=spans.size - 1)
        places[:, level] = offsets[level] + np.cumsum(held) - held
    return places


def tree_cells(points: Sorted, depth: int, split_above: float, threads: int | None = None,
               ) -> list[tuple[NDArray[np.int64], NDArray[np.float64], NDArray[np.bool_]]]:
    """Per level ``0..depth``: sorted keys, rows ``n, mean.., m2.., max..`` and split
    flags (``n > split_above`` above the finest level) of the root and the children of
    split cells of :func:`sort_points`' points (views of one buffer per array).

    Large inputs are walked on ``threads`` (default: numba's) side by side, one group of
    the cells of level ``_SPLIT_LEVEL`` each, with the same rows bit for bit."""
    assert split_above >= 1.0, "the walk skips cells of one point: they must not split"
    packed, shift, values = points
    flags = (depth, float(split_above))
    counts, firsts = _tree_counts(packed, shift, depth, flags[1])
    offsets = np.zeros(depth + 2, np.int64)
    offsets[1:] = np.cumsum(counts)
    width, at = 1 + 3 * values.shape[1], offsets[:-1].copy()
    out = (*_output(int(offsets[-1]), width), at)
    threads = numba.get_num_threads() if threads is None else threads
    floor = min(_SPLIT_LEVEL, depth) if threads > 1 and len(packed) >= CLOUD_MIN else 0
    if floor:  # the floor cells' subtrees in parallel, then the levels above
        spans = _run_starts(packed, shift + 2 * (depth - floor))
        size = spans.size - 1
        groups = np.r_[0, np.searchsorted(spans[:-1], np.arange(1, threads) * len(packed)
                                          / threads), size]
        cells = (np.empty((size, width)), np.empty(size, np.int64))
        places = _places(spans, firsts, offsets, floor)
        _walk_groups(points, (spans, groups, floor), flags, (*out[:3], places), cells)
        _walk_top(cells, floor, flags, out)
        at[floor + 1:] = places[-1, floor + 1:]
    elif len(packed):
        cells = (np.empty((1, width)), np.empty(1, np.int64))
        _walk(points, (0, len(packed), 0), flags, out, (*cells, 0))
        _emit(cells, (0, 1), 0, flags, out)
    assert (at == offsets[1:]).all(), "the walk wrote the cells the count found"
    return [(out[1][a:b], out[0][a:b], out[2][a:b]) for a, b in itertools.pairwise(offsets)]
