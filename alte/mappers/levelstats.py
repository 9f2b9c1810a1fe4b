"""Per-level sufficient statistics of the 2D mappers' cells, with amortised updates.

For every level ``0..depth`` of a square domain this keeps the sorted Morton keys of
the non-empty cells and, per cell, the count ``n`` and for each value column its mean,
``M2`` (sum of squared deviations, merged with Chan's parallel formula) and maximum.
Known cells are updated in place; new cells go to a level's *pending* part, folded into
the sorted part only when it outgrows a quarter of it or a reader needs it, so the
copying is amortised like a doubling array (see :class:`LevelStats`).
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

import numba
import numpy as np

from alte.errors import MapperError

__all__ = ["MAX_DEPTH", "LevelStats"]

#: Deepest level: 2 x 24 bits of Morton key per cell.
MAX_DEPTH = 24


def _segments(keys: np.ndarray) -> np.ndarray:
    """Start index of every run of equal values in sorted ``keys``."""
    return np.flatnonzero(np.r_[True, keys[1:] != keys[:-1]])


def _aggregate_points(values: np.ndarray, starts: np.ndarray) -> np.ndarray:
    """Rows ``n, mean.., m2.., max..`` of runs of points (values sorted by cell)."""
    counts = np.diff(np.r_[starts, len(values)]).astype(np.float64)
    mean = np.add.reduceat(values, starts, axis=0) / counts[:, None]
    dev = values - np.repeat(mean, counts.astype(np.int64), axis=0)
    m2 = np.add.reduceat(dev * dev, starts, axis=0)
    return np.column_stack([counts, mean, m2, np.maximum.reduceat(values, starts, axis=0)])


@numba.njit(cache=True)
def _run_sum(x: np.ndarray, a: int, b: int) -> float:
    """``x[a] + (x[a+1] + ... + x[b-1])``: the order of ``np.add.reduceat`` on short runs."""
    first: float = x[a]
    if b - a == 1:
        return first
    rest = x[a + 1]
    for i in range(a + 2, b):
        rest += x[i]
    total: float = first + rest
    return total


@numba.njit(cache=True)
def _combine(rows: np.ndarray, starts: np.ndarray, nv: int) -> np.ndarray:
    """Merge runs of aggregate rows (children -> parent) with Chan's formula.

    Compiled (the build's hot loop); ``sum(n_j c_j) / n`` and ``sum(M2_j + n_j (c_j - c)^2)``
    in numpy's order, so runs of up to 4 children give the bits of the reduceat form.
    """
    out = np.empty((len(starts), rows.shape[1]))
    term = np.empty(len(rows))
    for s in range(len(starts)):
        a, b = starts[s], starts[s + 1] if s + 1 < len(starts) else len(rows)
        out[s, 0] = count = _run_sum(rows[:, 0], a, b)
        for j in range(nv):
            for i in range(a, b):
                term[i] = rows[i, 0] * rows[i, 1 + j]
            out[s, 1 + j] = mean = _run_sum(term, a, b) / count
            for i in range(a, b):
                dev = rows[i, 1 + j] - mean
                term[i] = rows[i, 1 + nv + j] + rows[i, 0] * dev * dev
            out[s, 1 + nv + j] = _run_sum(term, a, b)
            out[s, 1 + 2 * nv + j] = rows[a:b, 1 + 2 * nv + j].max()
    return out


def _pair(a: np.ndarray, b: np.ndarray, nv: int) -> np.ndarray:
    """Merge aggregate rows ``a`` and ``b`` element-wise."""
    na, nb = a[:, :1], b[:, :1]
    n = na + nb
    delta = b[:, 1:1 + nv] - a[:, 1:1 + nv]
    mean = a[:, 1:1 + nv] + delta * (nb / n)
    m2 = a[:, 1 + nv:1 + 2 * nv] + b[:, 1 + nv:1 + 2 * nv] + delta * delta * (na * nb / n)
    return np.column_stack([n, mean, m2, np.maximum(a[:, 1 + 2 * nv:], b[:, 1 + 2 * nv:])])


_PENDING_FRACTION = 0.25  # fold a level once its pending cells exceed this share of the sorted
_PENDING_MIN = 4096  # ... and this many


class _PerLevel:
    """``stats.keys``/``rows``/``split``: level ``l``'s sorted array (a view of its storage)."""

    def __init__(self, stats: LevelStats, store: list[np.ndarray]) -> None:
        self._stats, self._store = stats, store

    def __len__(self) -> int:
        return len(self._store)

    def __iter__(self) -> Iterator[np.ndarray]:
        return (self[level] for level in range(len(self)))

    def __getitem__(self, level: int) -> np.ndarray:
        self._stats.fold(level)
        return self._store[level][:self._stats.size(level)]

    def __setitem__(self, level: int, value: np.ndarray) -> None:
        view = self[level]
        if np.shape(value)[:1] != view.shape[:1]:
            raise MapperError(f"level {level}: {np.shape(value)[:1]} values for "
                              f"{len(view)} cells")
        view[...] = value


class LevelStats:
    """Per level: sorted Morton keys, aggregate rows ``n, mean, m2, max`` and a split flag.

    Each level stores its cells in arrays with growth slack: a prefix sorted by key,
    then *pending* cells in arrival order found through a small sorted index. Readers
    (``keys[l]``, ``rows[l]``, ``split[l]``, :meth:`column`, :meth:`leaves`) fold the
    pending cells in first, so they always see sorted arrays; inside :meth:`deferred`
    nothing folds and row numbers are the ones :meth:`add` returned.
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
        self._pk = [np.empty(0, np.int64) for _ in levels]  # pending keys, sorted
        self._ps = [np.empty(0, np.int64) for _ in levels]  # ... and their storage slots
        self._defer = 0
        self.keys = _PerLevel(self, self._k)
        self.rows = _PerLevel(self, self._r)
        self.split = _PerLevel(self, self._s)

    def size(self, level: int) -> int:
        """Number of cells at ``level``."""
        return self._n[level]

    def column(self, level: int, what: str, j: int = 0) -> np.ndarray:
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

    def add(self, fine_keys: np.ndarray, values: np.ndarray) -> list[np.ndarray]:
        """Add points given by finest-level keys and (N, nv) values; rows touched per level."""
        order = np.argsort(fine_keys, kind="stable")
        keys = fine_keys[order]
        starts = _segments(keys)
        agg = _aggregate_points(values[order], starts)
        keys = keys[starts]
        touched: list[np.ndarray] = [np.empty(0, np.int64)] * (self.depth + 1)
        for level in range(self.depth, -1, -1):
            if level < self.depth:
                keys = keys >> 2
                starts = _segments(keys)
                agg = _combine(agg, starts, self.nv)
                keys = keys[starts]
            touched[level] = self._merge(level, keys, agg)
        return touched

    def _merge(self, level: int, keys: np.ndarray, agg: np.ndarray) -> np.ndarray:
        if not self._n[level]:  # empty level (a build): take the arrays as they are
            self._k[level], self._r[level] = keys, agg
            self._s[level] = np.zeros(len(keys), bool)
            self._n[level] = self._sorted[level] = len(keys)
            return np.arange(len(keys))
        slot = self._find(level, keys)
        hit = slot >= 0
        rows = self._r[level]
        rows[slot[hit]] = _pair(rows[slot[hit]], agg[hit], self.nv)
        if hit.all():
            return slot
        slot[~hit] = self._append(level, keys[~hit], agg[~hit])
        pending = self._n[level] - self._sorted[level]
        if pending > max(_PENDING_MIN, _PENDING_FRACTION * self._sorted[level]) and not self._defer:
            self.fold(level)
            return np.searchsorted(self._k[level][:self._n[level]], keys)
        return slot

    def _find(self, level: int, keys: np.ndarray) -> np.ndarray:
        """Storage slot of each (sorted, unique) key at ``level``; -1 when absent."""
        slot = np.full(len(keys), -1, np.int64)
        for have, where in ((self._k[level][:self._sorted[level]], None),
                            (self._pk[level], self._ps[level])):
            rest = np.flatnonzero(slot < 0)
            pos = np.searchsorted(have, keys[rest])
            ok = pos < len(have)
            ok[ok] = have[pos[ok]] == keys[rest[ok]]
            slot[rest[ok]] = pos[ok] if where is None else where[pos[ok]]
        return slot

    def _append(self, level: int, keys: np.ndarray, agg: np.ndarray) -> np.ndarray:
        """Store new cells after the others and index them as pending; their slots."""
        n, k = self._n[level], len(keys)
        if n + k > len(self._k[level]):  # grow the storage, doubling
            cap = max(n + k, 2 * len(self._k[level]))
            for store in (self._k, self._r, self._s):
                grown = np.empty((cap, *store[level].shape[1:]), store[level].dtype)
                grown[:n] = store[level][:n]
                store[level] = grown
        self._k[level][n:n + k] = keys
        self._r[level][n:n + k] = agg
        self._s[level][n:n + k] = False
        slots = np.arange(n, n + k)
        at = np.searchsorted(self._pk[level], keys)
        self._pk[level] = np.insert(self._pk[level], at, keys)
        self._ps[level] = np.insert(self._ps[level], at, slots)
        self._n[level] = n + k
        return slots

    def fold(self, level: int) -> None:
        """Merge ``level``'s pending cells into its sorted prefix (not while deferred)."""
        n, done = self._n[level], self._sorted[level]
        if n == done or self._defer:
            return
        dest = np.searchsorted(self._k[level][:done], self._pk[level])
        dest += np.arange(len(dest))  # final places of the pending cells, in key order
        first = int(dest[0])  # the sorted cells before it stay put
        order = np.empty(n - first, np.int64)
        moved = np.ones(n - first, bool)
        moved[dest - first] = False
        order[moved] = np.arange(first, done)
        order[dest - first] = self._ps[level]
        for store in (self._k, self._r, self._s):
            store[level][first:n] = store[level][order]
        self._sorted[level] = n
        self._pk[level] = self._ps[level] = np.empty(0, np.int64)

    def shift_up(self, quadrant: int) -> None:
        """Re-key for a root twice as large holding the old root in ``quadrant`` (0-3).

        Level ``l`` becomes level ``l + 1``; the new root has the old root's statistics
        and the old finest level is dropped (the depth limit is relative to the root).
        """
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

    @property
    def nbytes(self) -> int:
        """Bytes of the cells' keys, rows and flags (not counting storage growth slack)."""
        row = 8 * (1 + 3 * self.nv)
        return sum(n * (8 + row + 1) for n in self._n)

    def leaves(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
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
