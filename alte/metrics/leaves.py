"""What the truth says of each leaf of one map geometry, computed once per leaf.

Maps fed once and read with other occupancy rules (``Mapper.reread``) share their
leaves and differ in which are occupied; a map measured with another set B has the very
same cells. :class:`LeafTruth` keeps, per leaf asked about so far, its centre's distance
to the true surface, whether its centre lies inside a solid, and the surface samples
within the tolerance of its box, so each further map pays only for leaves not seen yet
and for the reductions (:mod:`alte.metrics.reference` uses it). Each value is the one
:mod:`alte.metrics.truth` computes: the same call on the same point, or the same box
distance of the same candidate pair.
"""

from __future__ import annotations

from collections.abc import Callable, Hashable
from typing import TYPE_CHECKING, Generic, TypeVar

import numpy as np
from numpy.typing import NDArray
from scipy.spatial import cKDTree

from alte.mappers._rows import unique_sorted
from alte.metrics.truth import TruthValues, accuracy_of, size_groups

if TYPE_CHECKING:
    from alte.metrics.surface import TrueSurface

__all__ = ["LeafTruth", "PerLeaf"]

#: What a :class:`PerLeaf` holds: distances or inside flags.
_V = TypeVar("_V", np.float64, np.bool_)


class PerLeaf(Generic[_V]):
    """Values of some leaves (sorted leaf rows), computed on first request."""

    def __init__(self, dtype: type[_V]) -> None:
        self.rows = np.empty(0, np.intp)
        self.values: NDArray[_V] = np.empty(0, dtype)

    def _positions(self, rows: NDArray[np.intp]) -> tuple[NDArray[np.intp], NDArray[np.bool_]]:
        pos = np.minimum(np.searchsorted(self.rows, rows), max(len(self.rows) - 1, 0))
        have = (self.rows[pos] == rows) if len(self.rows) else np.zeros(len(rows), bool)
        return pos, have

    def get(self, rows: NDArray[np.intp], compute: Callable[[NDArray[np.intp]], NDArray[_V]]
            ) -> NDArray[_V]:
        """The values of ``rows`` (int, any order, repeats allowed); ``compute`` gets the
        sorted rows not known yet and returns their values."""
        pos, have = self._positions(rows)
        if not have.all():
            new = unique_sorted(rows[~have])
            keys = np.concatenate([self.rows, new])
            order = np.argsort(keys, kind="stable")
            self.rows = keys[order]
            self.values = np.concatenate([self.values, compute(new)])[order]
            pos, _ = self._positions(rows)
        out: NDArray[_V] = self.values[pos]
        return out


class LeafTruth:
    """Per-leaf truth of the leaves with these ``centers`` and ``sizes`` (module docstring)."""

    def __init__(self, centers: NDArray[np.float64], sizes: NDArray[np.float64]) -> None:
        self.centers, self.sizes = centers, sizes
        self._distance = PerLeaf(np.float64)
        self._inside = PerLeaf(np.bool_)
        self._paired = np.zeros(len(centers), bool)  # leaves whose sample pairs are known
        # (sample, leaf) pairs within the tolerance
        self._pairs: list[tuple[NDArray[np.int64], NDArray[np.int64]]] = []
        self._tolerance: float | None = None
        self._memo: dict[Hashable, TruthValues] = {}

    def __len__(self) -> int:
        return len(self.centers)

    def matches(self, centers: NDArray[np.float64], sizes: NDArray[np.float64]) -> bool:
        """True for the same leaves (the same arrays, or equal ones)."""
        if centers is self.centers and sizes is self.sizes:
            return True
        return (centers.shape == self.centers.shape and sizes.shape == self.sizes.shape
                and np.array_equal(centers, self.centers, equal_nan=True)
                and np.array_equal(sizes, self.sizes, equal_nan=True))

    def memo(self, key: Hashable, compute: Callable[[], TruthValues]) -> TruthValues:
        """``compute()``, once per ``key`` for these leaves."""
        if key not in self._memo:
            self._memo[key] = compute()
        return self._memo[key]

    def accuracy(self, mask: NDArray[np.bool_], surface: TrueSurface, tolerance: float
                 ) -> TruthValues:
        """:func:`~alte.metrics.truth.accuracy` of the leaves in ``mask``."""
        rows = np.flatnonzero(mask)
        dist = self._distance.get(rows, lambda r: surface.distance(self.centers[r]))
        return accuracy_of(dist, self.sizes[rows], tolerance)

    def inside(self, rows: NDArray[np.intp], surface: TrueSurface) -> NDArray[np.bool_]:
        """:meth:`TrueSurface.inside` of the centres of leaves ``rows``."""
        return self._inside.get(rows, lambda r: surface.inside(self.centers[r]))

    def covered(self, mask: NDArray[np.bool_], points: NDArray[np.float64], tree: cKDTree,
                tolerance: float) -> NDArray[np.bool_]:
        """Per sample (``points``, ``tree`` over them): is a box of ``mask`` within
        ``tolerance`` (:func:`~alte.metrics.truth.completeness`)?"""
        if self._tolerance not in (None, tolerance):
            raise ValueError("leaf truth: one tolerance per geometry")
        self._tolerance = tolerance
        new = np.flatnonzero(mask & ~self._paired)
        if new.size:
            self._pairs.append(self._near_pairs(points, tree, new, tolerance))
            self._paired[new] = True
        out = np.zeros(len(points), bool)
        for sample, leaf in self._pairs:
            out[sample[mask[leaf]]] = True
        return out

    def _near_pairs(self, points: NDArray[np.float64], tree: cKDTree, rows: NDArray[np.intp],
                    tolerance: float) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
        """(sample, leaf) pairs of the leaves ``rows`` whose box lies within ``tolerance``:
        :func:`~alte.metrics.truth.distance_to_boxes`' candidates (per size group, centres
        within half a diagonal plus the tolerance) and its box distance."""
        half = np.asarray(self.sizes[rows], dtype=np.float64) / 2.0
        groups, inverse = size_groups(half)
        found: list[tuple[NDArray[np.intp], NDArray[np.intp]]] = []
        for g, h in enumerate(groups):
            sel = rows[inverse.reshape(-1) == g]
            radius = float(np.linalg.norm(h)) + tolerance
            pairs = tree.sparse_distance_matrix(cKDTree(self.centers[sel]), radius,
                                                output_type="ndarray")
            if len(pairs) == 0:
                continue
            i, j = pairs["i"], sel[pairs["j"]]
            gap = np.maximum(np.abs(points[i] - self.centers[j]) - h, 0.0)
            near = ~(np.linalg.norm(gap, axis=1) > tolerance)
            found.append((i[near], j[near]))
        if not found:
            return np.empty(0, np.int64), np.empty(0, np.int64)
        return (np.concatenate([f[0] for f in found]).astype(np.int64),
                np.concatenate([f[1] for f in found]).astype(np.int64))
