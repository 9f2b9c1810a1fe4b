"""Sparse per-level cell statistics on a square domain: the engine of the 2D mappers.

Level ``l`` divides the square root domain into ``2^l x 2^l`` cells; a cell is named
by the Morton key of its integer indices, so a parent's key is its child's key
``>> 2`` and sorted child keys group by parent. For every level ``0..depth`` we keep
the sorted keys of the non-empty cells and, per cell, the count ``n`` and for each
value column its mean, ``M2`` (sum of squared deviations, merged with Chan's parallel
formula: no cancellation when heights are equal) and maximum.

Adding points sorts them once at the finest level and merges aggregates upwards, so
the arithmetic is proportional to the new points (times the depth); new cells are
spliced into the sorted arrays with ``np.insert``, a memory move of the level's
arrays. That move dominates deep, fine trees (Quadtree, depth 12, 465k points:
about 40 ms per 930-point frame) and is negligible for 2D-ALTE's few thousand cells.
The statistics of a cloud do not depend on how it was cut into
frames (up to floating-point rounding of the sums), which is what makes the mappers'
incremental insertion equal their batch build.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from alte.errors import MapperError

__all__ = ["LevelStats", "Square", "morton_decode", "morton_encode", "parse_domain"]

_MAX_DEPTH = 24


def _part1by1(v: np.ndarray) -> np.ndarray:
    v = v.astype(np.uint64) & np.uint64(0x00000000FFFFFFFF)
    for shift, mask in ((16, 0x0000FFFF0000FFFF), (8, 0x00FF00FF00FF00FF),
                        (4, 0x0F0F0F0F0F0F0F0F), (2, 0x3333333333333333),
                        (1, 0x5555555555555555)):
        v = (v | (v << np.uint64(shift))) & np.uint64(mask)
    return v


def _compact1by1(v: np.ndarray) -> np.ndarray:
    v = v.astype(np.uint64) & np.uint64(0x5555555555555555)
    for shift, mask in ((1, 0x3333333333333333), (2, 0x0F0F0F0F0F0F0F0F),
                        (4, 0x00FF00FF00FF00FF), (8, 0x0000FFFF0000FFFF),
                        (16, 0x00000000FFFFFFFF)):
        v = (v | (v >> np.uint64(shift))) & np.uint64(mask)
    return v


def morton_encode(ix: np.ndarray, iy: np.ndarray) -> np.ndarray:
    """Interleave cell indices (x in the even bits) into int64 keys."""
    return (_part1by1(ix) | (_part1by1(iy) << np.uint64(1))).astype(np.int64)


def morton_decode(keys: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Inverse of :func:`morton_encode`."""
    k = np.asarray(keys).astype(np.uint64)
    return (_compact1by1(k).astype(np.int64), _compact1by1(k >> np.uint64(1)).astype(np.int64))


@dataclass(frozen=True)
class Square:
    """The root cell ``[xmin, xmin + size] x [ymin, ymin + size]`` (closed)."""

    xmin: float
    ymin: float
    size: float

    @classmethod
    def bounding(cls, xy: np.ndarray) -> Square:
        """Smallest square anchored at the minimum corner holding ``xy`` (size 1 if a point)."""
        lo = xy.min(axis=0)
        size = float((xy.max(axis=0) - lo).max())
        return cls(float(lo[0]), float(lo[1]), size if size > 0 else 1.0)

    @classmethod
    def dyadic(cls, xy: np.ndarray) -> Square:
        """Power-of-two square on a grid of its own size holding ``xy`` (root of a growing map)."""
        lo = xy.min(axis=0)
        extent = float((xy.max(axis=0) - lo).max())
        size = float(np.exp2(np.ceil(np.log2(extent)))) if extent > 0 else 1.0
        xmin, ymin = np.floor(lo / size) * size
        return cls(float(xmin), float(ymin), size)

    def contains(self, xy: np.ndarray, closed: bool = True) -> np.ndarray:
        """Mask of the points inside the square; ``closed=False`` excludes the upper edges."""
        rel = (xy - (self.xmin, self.ymin)) / self.size
        upper = (rel <= 1.0) if closed else (rel < 1.0)
        return ((rel >= 0.0) & upper).all(axis=1)

    def keys(self, xy: np.ndarray, level: int) -> np.ndarray:
        """Morton keys of the level-``level`` cells holding ``xy`` (upper edge -> last cell)."""
        cells = 1 << level
        rel = (xy - (self.xmin, self.ymin)) / self.size
        idx = np.clip(np.floor(rel * cells), 0, cells - 1).astype(np.int64)
        return morton_encode(idx[:, 0], idx[:, 1])

    def doubled(self, xy: np.ndarray) -> tuple[Square, int]:
        """Twice as large a square towards the points outside; returns it and the old quadrant."""
        ox = int(bool((xy[:, 0] < self.xmin).any()))
        oy = int(bool((xy[:, 1] < self.ymin).any()))
        grown = Square(self.xmin - ox * self.size, self.ymin - oy * self.size, 2 * self.size)
        return grown, ox + 2 * oy

    def cell_geometry(self, level: np.ndarray, keys: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Centres (K, 2) and edge lengths (K,) of cells given by level and key."""
        ix, iy = morton_decode(keys)
        edge = self.size / np.exp2(level)
        centers = np.column_stack([self.xmin + (ix + 0.5) * edge, self.ymin + (iy + 0.5) * edge])
        return centers, edge


def parse_domain(text: str) -> Square | None:
    """``"xmin,ymin,size"`` or ``"xmin,ymin,zmin,size"`` (zmin ignored); ``""`` -> None."""
    if not text.strip():
        return None
    values = [float(v) for v in text.split(",")]
    if len(values) not in (3, 4) or not np.isfinite(values).all() or values[-1] <= 0:
        raise ValueError(f"domain {text!r}: expected xmin,ymin,size with size > 0")
    return Square(values[0], values[1], values[-1])


def domain_ok(text: str) -> bool:
    """True when :func:`parse_domain` accepts ``text``."""
    try:
        parse_domain(text)
    except ValueError:
        return False
    return True


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


def _combine(rows: np.ndarray, starts: np.ndarray, nv: int) -> np.ndarray:
    """Merge runs of aggregate rows (children -> parent) with Chan's formula."""
    n_j = rows[:, 0]
    means = rows[:, 1:1 + nv]
    counts = np.add.reduceat(n_j, starts)
    mean = np.add.reduceat(n_j[:, None] * means, starts, axis=0) / counts[:, None]
    sizes = np.diff(np.r_[starts, len(rows)])
    dev = means - np.repeat(mean, sizes, axis=0)
    m2 = np.add.reduceat(rows[:, 1 + nv:1 + 2 * nv] + n_j[:, None] * dev * dev, starts, axis=0)
    mx = np.maximum.reduceat(rows[:, 1 + 2 * nv:], starts, axis=0)
    return np.column_stack([counts, mean, m2, mx])


def _pair(a: np.ndarray, b: np.ndarray, nv: int) -> np.ndarray:
    """Merge aggregate rows ``a`` and ``b`` element-wise."""
    na, nb = a[:, :1], b[:, :1]
    n = na + nb
    delta = b[:, 1:1 + nv] - a[:, 1:1 + nv]
    mean = a[:, 1:1 + nv] + delta * (nb / n)
    m2 = a[:, 1 + nv:1 + 2 * nv] + b[:, 1 + nv:1 + 2 * nv] + delta * delta * (na * nb / n)
    return np.column_stack([n, mean, m2, np.maximum(a[:, 1 + 2 * nv:], b[:, 1 + 2 * nv:])])


class LevelStats:
    """Per level: sorted Morton keys, aggregate rows ``n, mean, m2, max`` and a split flag."""

    def __init__(self, depth: int, nvalues: int) -> None:
        if not 0 <= depth <= _MAX_DEPTH:
            raise MapperError(f"tree depth {depth} outside 0..{_MAX_DEPTH}")
        self.depth = depth
        self.nv = nvalues
        self.keys = [np.empty(0, np.int64) for _ in range(depth + 1)]
        self.rows = [np.empty((0, 1 + 3 * nvalues)) for _ in range(depth + 1)]
        self.split = [np.empty(0, bool) for _ in range(depth + 1)]

    def column(self, level: int, what: str, j: int = 0) -> np.ndarray:
        """Column ``n``, ``mean``, ``m2`` or ``max`` (of value ``j``) at ``level``."""
        offset = {"n": 0, "mean": 1, "m2": 1 + self.nv, "max": 1 + 2 * self.nv}[what]
        return self.rows[level][:, offset + (0 if what == "n" else j)]

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
        old = self.keys[level]
        pos = np.searchsorted(old, keys)
        found = pos < len(old)
        found[found] = old[pos[found]] == keys[found]
        rows = self.rows[level]
        rows[pos[found]] = _pair(rows[pos[found]], agg[found], self.nv)
        new = pos[~found]
        if len(new):
            self.keys[level] = np.insert(old, new, keys[~found])
            self.rows[level] = np.insert(rows, new, agg[~found], axis=0)
            self.split[level] = np.insert(self.split[level], new, False)
        return np.searchsorted(self.keys[level], keys)

    def shift_up(self, quadrant: int) -> None:
        """Re-key for a root twice as large holding the old root in ``quadrant`` (0-3).

        Level ``l`` becomes level ``l + 1``; the new root has the old root's statistics
        and the old finest level is dropped (the depth limit is relative to the root).
        """
        for level in range(self.depth, 0, -1):
            self.keys[level] = self.keys[level - 1] + (quadrant << (2 * (level - 1)))
            self.rows[level] = self.rows[level - 1].copy()
        self.keys[0] = self.keys[0] * 0
        self.split = [np.zeros(len(k), bool) for k in self.keys]

    @property
    def nbytes(self) -> int:
        """Bytes held by the key, row and flag arrays."""
        return sum(k.nbytes + r.nbytes + s.nbytes
                   for k, r, s in zip(self.keys, self.rows, self.split, strict=True))

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
