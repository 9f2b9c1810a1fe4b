"""Per-level sufficient statistics of the 2D mappers' cells, with amortised updates.

For every level ``0..depth`` of a square domain this keeps the sorted Morton keys of
the non-empty cells and, per cell, the count ``n`` and for each value column its mean,
``M2`` (sum of squared deviations, merged with Chan's parallel formula) and maximum.
An insertion runs in compiled kernels (``_cellstats``): the frame's points are sorted
and aggregated once at the finest level and merged upwards; at each level a hash
index finds known cells, which are updated in place, and new cells are appended
after the others (*pending*). Pending cells are sorted in only when a reader needs
the sorted arrays, so an insertion costs O(frame x depth) whatever the map's size,
with no copying of the map (storage grows rarely: doubling, from a generous first
size that the OS pages in only as it is used).

A build whose cells split on their count alone keeps the tree of the partition only
(:meth:`LevelStats.build_tree`: one walk over the sorted points, ``_treebuild``) and
the sorted points, from which :meth:`LevelStats.complete` fills in every other cell
when an insertion needs them.
"""

from __future__ import annotations

import copy
from collections.abc import Iterator
from contextlib import contextmanager

import numpy as np
from numpy.typing import NDArray

from alte.errors import MapperError
from alte.mappers.quad.cellstats import (
    Index,
    aggregate_points,
    combine,
    fill_index,
    merge_cells,
    sort_keys,
)
from alte.mappers.quad.storage import PerLevel, lazy_zeros
from alte.mappers.quad.treebuild import Sorted, sort_points, tree_cells

__all__ = ["MAX_DEPTH", "LevelStats"]

#: Deepest level: 2 x 24 bits of Morton key per cell.
MAX_DEPTH = 24


#: Rows a level's storage first grows to when an insertion meets it (allocated lazily by
#: the OS: untouched rows cost no memory); it doubles from there.
_FIRST_CAPACITY = 1 << 22
#: Levels of at most this many cells (``4**level``) index their rows densely (4 bytes a
#: cell, paged in by the OS only where data lie); deeper levels hash.
_DENSE_CELLS = 1 << 24


class LevelStats:
    """Per level: sorted Morton keys, aggregate rows ``n, mean, m2, max`` and a split flag.

    Each level stores its cells in arrays with growth slack: a prefix sorted by key,
    then *pending* cells in arrival order; an index over all of them (dense or hashed,
    see ``_cellstats``; built when an insertion first needs it) finds a key's row.
    Readers (``keys[l]``, ``rows[l]``, ``split[l]``, :meth:`column`, :meth:`leaves`)
    fold the pending cells in first, so they always see sorted arrays; :meth:`add`
    never folds, and inside :meth:`deferred` nothing does, so row numbers stay the ones
    :meth:`add` returned.
    """

    def __init__(self, depth: int, nvalues: int) -> None:
        if not 0 <= depth <= MAX_DEPTH:
            raise MapperError(f"tree depth {depth} outside 0..{MAX_DEPTH}")
        self.depth = depth
        self.nv = nvalues
        levels = range(depth + 1)
        self._k = [np.empty(0, np.int64) for _ in levels]
        self._r = [np.empty((0, 1 + 3 * nvalues)) for _ in levels]
        self._s = [np.empty(0, bool) for _ in levels]
        self._n = [0 for _ in levels]  # cells held
        self._sorted = [0 for _ in levels]  # length of the sorted prefix
        self._index: list[Index | None] = [None for _ in levels]  # None: to rebuild
        self._defer = 0
        self._source: tuple[Sorted, float] | None = None  # see build_tree
        self._shared = False  # cells shared with a branch: no more points (see branch)
        #: Cell statistics written so far, every level (the maps' machine-free cost).
        self.updates = 0
        self.keys = PerLevel(self, self._k)
        self.rows = PerLevel(self, self._r)
        self.split = PerLevel(self, self._s)

    def size(self, level: int) -> int:
        """Number of cells at ``level``."""
        return self._n[level]

    def column(self, level: int, what: str, j: int = 0) -> NDArray[np.float64]:
        """Column ``n``, ``mean``, ``m2`` or ``max`` (of value ``j``) at ``level``."""
        offset = {"n": 0, "mean": 1, "m2": 1 + self.nv, "max": 1 + 2 * self.nv}[what]
        self.fold(level)
        return self._r[level][:self._n[level], offset + (0 if what == "n" else j)]

    @contextmanager
    def deferred(self) -> Iterator[None]:
        """No folding inside: row numbers from :meth:`add` stay valid (split updates)."""
        self._defer += 1
        try:
            yield
        finally:
            self._defer -= 1

    def add(self, fine_keys: NDArray[np.int64], values: NDArray[np.float64],
            ) -> list[NDArray[np.int64]] | None:
        """Add points given by finest-level keys and (N, nv) values; the rows touched per
        level, or None when the map was empty (every row is new)."""
        self._check_own()
        self.complete()
        was_empty = not any(self._n)
        keys, order = sort_keys(np.asarray(fine_keys, np.int64), 2 * self.depth)
        keys, agg = aggregate_points(keys, np.ascontiguousarray(values[order], float))
        touched: list[NDArray[np.int64]] = [np.empty(0, np.int64)] * (self.depth + 1)
        for level in range(self.depth, -1, -1):
            if level < self.depth:
                keys, agg = combine(keys, agg, self.nv)
            touched[level] = self._merge(level, keys, agg)
            self.updates += len(keys)
        return None if was_empty else touched

    def build_tree(self, fine_keys: NDArray[np.int64], values: NDArray[np.float64],
                   split_above: float) -> None:
        """Fill empty levels with the cells of a partition that splits a cell when its
        ``n > split_above``: the root and the children of split cells (``_treebuild``),
        with their split flags.

        The sorted points are kept, so that :meth:`complete` can add the other cells
        when an insertion or a shift of the root needs them. ``fine_keys`` is consumed:
        its buffer holds the sorted points' packed keys."""
        points = sort_points(fine_keys, values, 2 * self.depth, reuse_keys=True)
        for level, cells in enumerate(tree_cells(points, self.depth, split_above)):
            self._set_level(level, *cells)
            self.updates += len(cells[0])
        self._source = (points, split_above)

    def complete(self) -> None:
        """Every non-empty cell on every level (after :meth:`build_tree`, which keeps the
        tree's cells only): :meth:`add` of the kept points to empty levels, flagged."""
        if self._source is None:
            return
        (packed, shift, values), split_above = self._source
        self._source = None
        for level in range(self.depth + 1):
            self._set_level(level, np.empty(0, np.int64), np.empty((0, 1 + 3 * self.nv)),
                            np.empty(0, bool))
        if shift:  # in their sorted order: the stable sort of add keeps it
            values = values[packed & ((1 << shift) - 1)]
        self.add(packed >> shift, values)
        for level in range(self.depth):
            self._s[level] = self._r[level][:, 0] > split_above

    def branch(self) -> LevelStats:
        """A copy sharing the cells (keys and statistics) that owns its split flags, so a
        map can be read with another split rule. Neither takes points afterwards: an
        insertion would change the shared cells under the other."""
        for level in range(self.depth + 1):
            self.fold(level)
        other = copy.copy(self)
        other._k, other._r, other._s = list(self._k), list(self._r), [s.copy() for s in self._s]
        other._n, other._sorted, other._index = list(self._n), list(self._sorted), list(self._index)
        other.keys, other.rows = PerLevel(other, other._k), PerLevel(other, other._r)
        other.split = PerLevel(other, other._s)
        self._shared = other._shared = True
        return other

    def _check_own(self) -> None:
        if self._shared:
            raise MapperError("this map was re-read with other parameters and shares its cells "
                              "with the copy; build it afresh to add points")

    def _set_level(self, level: int, keys: NDArray[np.int64], rows: NDArray[np.float64],
                   split: NDArray[np.bool_]) -> None:
        """Replace ``level``'s cells by sorted ``keys`` with their rows and split flags."""
        self._k[level], self._r[level], self._s[level] = keys, rows, split
        self._n[level] = self._sorted[level] = len(keys)
        self._index[level] = None

    def _merge(self, level: int, keys: NDArray[np.int64],
               agg: NDArray[np.float64]) -> NDArray[np.int64]:
        if not self._n[level]:  # empty level: take the arrays as they are
            self._set_level(level, keys, agg, np.zeros(len(keys), bool))
            return np.arange(len(keys))
        index = self._reserve(level, len(keys))
        store = (self._k[level], self._r[level], self._s[level], index)
        touched, self._n[level] = merge_cells(store, self._n[level], (keys, agg), self.nv,
                                              self._dense(level))
        return touched

    def _dense(self, level: int) -> bool:
        return bool(4**level <= _DENSE_CELLS)

    def _reserve(self, level: int, k: int) -> Index:
        """Room for ``k`` more cells at ``level``; the index of its rows (a hashed one
        kept at most half full)."""
        n = self._n[level]
        if n + k > len(self._k[level]):
            cap = max(n + k, 2 * len(self._k[level]), min(4**level, _FIRST_CAPACITY))
            for store in (self._k, self._r, self._s):
                grown = lazy_zeros((cap, *store[level].shape[1:]), store[level].dtype)
                grown[:n] = store[level][:n]
                store[level] = grown
            if not self._dense(level):
                self._index[level] = None
        index = self._index[level]
        if index is None:
            if self._dense(level):
                index = lazy_zeros((4**level,), np.int32)
            else:
                index = np.full(2 << int(2 * len(self._k[level])).bit_length(), -1, np.int64)
            fill_index(index, self._k[level], n, self._dense(level))
            self._index[level] = index
        return index

    def fold(self, level: int) -> None:
        """Sort ``level``'s pending cells into its sorted prefix (not while deferred)."""
        n, done = self._n[level], self._sorted[level]
        if n == done or self._defer:
            return
        keys = self._k[level]
        slots = done + np.argsort(keys[done:n], kind="stable")
        dest = np.searchsorted(keys[:done], keys[slots])
        dest += np.arange(len(dest))  # final places of the pending cells, in key order
        first = int(dest[0])  # the sorted cells before it stay put
        order = np.empty(n - first, np.int64)
        moved = np.ones(n - first, bool)
        moved[dest - first] = False
        order[moved] = np.arange(first, done)
        order[dest - first] = slots
        for store in (self._k, self._r, self._s):
            store[level][first:n] = store[level][order]
        self._sorted[level] = n
        index = self._index[level]
        if index is not None:  # same keys, new rows
            fill_index(index, self._k[level], n, self._dense(level))

    def shift_up(self, quadrant: int) -> None:
        """Re-key for a root twice as large holding the old root in ``quadrant`` (0-3).

        Level ``l`` becomes level ``l + 1``; the new root has the old root's statistics
        and the old finest level is dropped (the depth limit is relative to the root).
        """
        self.complete()
        for level in range(self.depth + 1):
            self.fold(level)
        for level in range(self.depth, 0, -1):
            n = self._n[level - 1]
            self._k[level] = self._k[level - 1][:n] + (quadrant << (2 * (level - 1)))
            self._r[level] = self._r[level - 1][:n].copy()
            self._n[level] = self._sorted[level] = n
        self._k[0] = self._k[0][:self._n[0]] * 0
        self._r[0] = self._r[0][:self._n[0]]
        for level in range(self.depth + 1):
            self._s[level] = np.zeros(self._n[level], bool)
            self._index[level] = None

    @property
    def nbytes(self) -> int:
        """Bytes of the cells' keys, rows and flags, and of the points a tree build keeps:
        the map itself, not the insertion's growth slack or row index (up to 4 bytes per
        cell of a level's touched area)."""
        row = 8 * (1 + 3 * self.nv)
        kept = 0
        if self._source is not None:
            packed, _shift, values = self._source[0]
            kept = packed.nbytes + values.nbytes
        return sum(n * (8 + row + 1) for n in self._n) + kept

    def leaves(self) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.int64]]:
        """Partition by the split flags: (level, key, row or -1 for an empty cell) per leaf."""
        levels, keys, rows = [], [], []
        cand = np.zeros(1, np.int64)
        for level in range(self.depth + 1):
            have = self.keys[level]
            pos = np.minimum(np.searchsorted(have, cand), max(len(have) - 1, 0))
            found = (pos < len(have)) & (have[pos] == cand) if len(have) else cand < 0
            split = found & self.split[level][pos] if len(have) else found
            leaf = ~split
            levels.append(np.full(int(leaf.sum()), level, np.int64))
            keys.append(cand[leaf])
            rows.append(np.where(found, pos, -1)[leaf])
            cand = ((cand[split] << 2)[:, None] + np.arange(4)).ravel()
            if not len(cand):
                break
        return np.concatenate(levels), np.concatenate(keys), np.concatenate(rows)
