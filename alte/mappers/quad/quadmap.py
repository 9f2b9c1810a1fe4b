"""Common machinery of the two 2D mappers: domain, insertion, leaves, cells, corners.

A subclass names the value columns it keeps per cell (:meth:`QuadMap._values`),
decides splits from the statistics (:meth:`QuadMap._split`) and turns leaf
statistics into heights, values and occupancy (:meth:`QuadMap._leaf_values`).

Domain. A :class:`~alte.mappers.domain.Domain` fixes the root square before data arrive:
points outside it are dropped and counted in :attr:`QuadMap.points_outside`. With
no domain, :meth:`~QuadMap.build` uses the bounding square of the cloud, and the
first :meth:`~QuadMap.insert` uses a power-of-two square aligned on its own size holding
the first frame; later frames reaching outside it (upper edges excluded) grow the
root by doubling it towards them, which keeps
every existing cell boundary (cells move one level down; the finest level is
dropped, since depth limits count from the root). The map after such growth equals
a batch build with ``domain`` set to the grown root (:attr:`QuadMap.square`).
"""

from __future__ import annotations

import copy
from collections.abc import Mapping
from pathlib import Path
from typing import ClassVar, Self, TypeAlias

import numpy as np
from numpy.typing import NDArray

from alte.errors import MapperError
from alte.mappers._rows import unique_rows
from alte.mappers.base import (
    API_VERSION,
    CellCounts,
    Cells,
    Cost,
    Feed,
    check_points,
    check_view,
    parsed,
)
from alte.mappers.domain import Domain, DomainUse, check_domain
from alte.mappers.quad.levelstats import LevelStats
from alte.mappers.quad.quadgrid import Square
from alte.params import Record

__all__ = ["LeafValues", "QuadMap", "Rows", "plane_height", "rectangle_corners"]

#: Storage rows of a level's cells, or all of them (a slice: no gathered copy).
Rows: TypeAlias = "NDArray[np.int64] | slice[None, None, None]"
#: Per leaf: its height, its value and whether it is occupied.
LeafValues = tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.bool_]]


def plane_height(ground: float | NDArray[np.float64], xy: NDArray[np.float64],
                 ) -> NDArray[np.float64]:
    """Height of the ground at ``xy``: a float z, or a plane ``(a, b, c, d)``: ax+by+cz+d=0."""
    plane = np.asarray(ground, dtype=np.float64).reshape(-1)
    if plane.shape == (1,):
        return np.full(len(xy), plane[0])
    if plane.shape != (4,) or not np.isfinite(plane).all() or abs(plane[2]) < 1e-9:
        raise ValueError(f"ground {plane.tolist()}: expected a z value or a non-vertical plane "
                         "a,b,c,d (a x + b y + c z + d = 0)")
    height: NDArray[np.float64] = -(plane[0] * xy[:, 0] + plane[1] * xy[:, 1] + plane[3]) / plane[2]
    return height


def rectangle_corners(cells: Cells, mask: NDArray[np.bool_]) -> NDArray[np.float64]:
    """The 4 corners (at the cell's height) of the masked 2D cells, de-duplicated."""
    c = cells.centers[mask]
    half = cells.sizes[mask, :2] / 2
    signs = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]], dtype=np.float64)
    xy = (c[:, None, :2] + signs[None] * half[:, None]).reshape(-1, 2)
    pts = np.column_stack([xy, np.repeat(c[:, 2], 4)])
    return unique_rows(pts)


class QuadMap:
    """Base of the 2D mappers (Quadtree, 2D-ALTE); see the module docstring."""

    api_version: ClassVar[int] = API_VERSION
    name: ClassVar[str] = "quadmap"
    title: ClassVar[str] = "quadmap"
    dims: ClassVar[int] = 2
    incremental: ClassVar[bool] = True
    domain_use: ClassVar[DomainUse] = DomainUse.OPTIONAL
    default_feed: ClassVar[Feed] = Feed.FRAMES
    exports: ClassVar[frozenset[str]] = frozenset({".npz"})
    free_space: ClassVar[bool] = False
    cost_unit: ClassVar[Cost] = Cost.CELL_UPDATES
    Settings: ClassVar[type[Record]] = Record
    view_params: ClassVar[frozenset[str]] = frozenset()
    layers: ClassVar[frozenset[str]] = frozenset()
    settings_grid: ClassVar[Mapping[str, tuple[object, ...]]] = {}
    _NVALUES: ClassVar[int] = 1

    def __init__(self, domain: Domain | None = None, *, record: Record | None = None,
                 **given: object) -> None:
        domain = check_domain(self.name, domain)
        self._record = parsed(self.Settings, record, given)
        self._params = self._record.as_dict()
        self._zmin = 0.0 if domain is None else domain.zmin
        self._fixed = None if domain is None else Square(domain.xmin, domain.ymin, domain.size)
        self._reset(self._fixed)

    # -- hooks ---------------------------------------------------------------------------
    @property
    def depth(self) -> int:
        """Deepest tree level allowed (root = 0)."""
        raise NotImplementedError

    def _values(self, points: NDArray[np.float64]) -> NDArray[np.float64]:
        raise NotImplementedError

    def _split(self, level: int, rows: Rows) -> NDArray[np.bool_]:
        raise NotImplementedError

    def _split_above(self) -> float | None:
        """The count over which a cell splits, when :meth:`_split` is ``n > count`` above
        the deepest level and nothing else: a build then keeps the partition's cells only
        (:meth:`LevelStats.build_tree`). None: :meth:`_split` decides, on every cell."""
        return None

    def _update_splits(self, touched: list[NDArray[np.int64]] | None) -> None:
        """Recompute the split flags of the ``touched`` rows per level (None: all rows,
        as a slice: no gathering of whole columns).

        Deferred: ``touched`` are storage rows that a fold of pending cells would move.
        """
        with self.stats.deferred():
            for level in range(self.depth + 1):
                rows = slice(None) if touched is None else touched[level]
                self.stats.split[level][rows] = self._split(level, rows)

    def _leaf_values(self, level: NDArray[np.int64], rows: NDArray[np.int64],
                     centers: NDArray[np.float64]) -> LeafValues:
        raise NotImplementedError

    # -- protocol ------------------------------------------------------------------------
    @property
    def params(self) -> Record:
        """The validated parameters, defaults filled in."""
        return self._record

    @property
    def domain(self) -> Domain | None:
        """The root square (the given domain, or the one grown from the data so far)."""
        if self.square is None:
            return None
        return Domain(self.square.xmin, self.square.ymin, self._zmin, self.square.size)

    @property
    def cost(self) -> int:
        """Points located plus cell statistics written on every level (:class:`Cost`)."""
        return self.points_inserted + self.stats.updates

    def write_native(self, path: Path, overwrite: bool = False) -> Path:
        """2D maps have no format of their own: export ``.npz`` cells instead."""
        raise MapperError(f"{self.name}: no native map format; export .npz instead")

    def _reset(self, square: Square | None) -> None:
        self.square: Square | None = square
        self.stats = LevelStats(self.depth, self._NVALUES)
        self.points_outside = 0
        self.points_inserted = 0
        self._cells: Cells | None = None

    def insert(self, points: NDArray[np.float64], origin: NDArray[np.float64]) -> None:
        """Add one registered frame; ``origin`` is checked but unused by a height map."""
        pts = check_points(points, self.name)
        check_points(np.reshape(origin, (1, -1)), self.name, "origin")
        if not len(pts):
            return
        if self.square is None:
            self.square = Square.dyadic(pts[:, :2])
        if self._fixed is None:
            self._grow(pts[:, :2])
        self._add(pts)

    def build(self, points: NDArray[np.float64],
              origins: NDArray[np.float64] | None = None) -> None:
        """Replace the map by one built from a whole cloud (``origins`` unused)."""
        pts = check_points(points, self.name)
        square = self._fixed
        if square is None and len(pts):
            square = Square.bounding(pts[:, :2])
        self._reset(square)
        if len(pts):
            self._add(pts, batch=True)

    def reread(self, **changes: object) -> Self:
        """This map read with other ``view_params`` (:meth:`alte.mappers.base.Mapper.reread`):
        the cells' statistics are shared, the split flags recomputed from them, which
        gives the flags an insertion with those values would have left (a cell's rule
        reads its own final statistics)."""
        check_view(self, changes)
        record = self._record.replace(**changes)
        other = copy.copy(self)
        other._record, other._params, other._cells = record, record.as_dict(), None
        other.stats = self.stats.branch()
        other._update_splits(None)
        return other

    def _grow(self, xy: NDArray[np.float64]) -> None:
        assert self.square is not None  # callers set the root square first
        grown = False
        square = self._root()
        while not square.contains(xy, closed=False).all():
            square, quadrant = square.doubled(xy)
            self.square = square
            self.stats.shift_up(quadrant)
            grown = True
        if grown:
            self._update_splits(None)

    def _root(self) -> Square:
        assert self.square is not None, "insert and build set the root before adding points"
        return self.square

    def _add(self, pts: NDArray[np.float64], batch: bool = False) -> None:
        keys, inside = self._root().locate(pts[:, :2], self.depth)
        kept = int(np.count_nonzero(inside))
        self.points_outside += len(pts) - kept
        if kept < len(pts):
            pts, keys = pts[inside], keys[inside]
        self._cells = None
        if not kept:
            return
        self.points_inserted += kept
        above = self._split_above()
        if batch and above is not None:  # the partition's cells only (LevelStats.build_tree)
            self.stats.build_tree(keys, self._values(pts), above)
            return
        self._update_splits(self.stats.add(keys, self._values(pts)))

    def cell_counts(self) -> CellCounts:
        """Counts of :meth:`cells` (small maps: the table itself)."""
        return CellCounts.of(self.cells())

    def cells(self) -> Cells:
        """Leaves of the partition; unknown (empty) leaves have NaN height and value."""
        if self._cells is None:
            self._cells = self._make_cells()
        return self._cells

    def _make_cells(self) -> Cells:
        if self.square is None:
            empty = np.empty((0, 3))
            return Cells(empty, empty.copy(), np.empty(0), np.empty(0, bool),
                         np.empty(0, np.int64))
        level, keys, rows = self.stats.leaves()
        xy, edge = self.square.cell_geometry(level, keys)
        z, value, occupied = self._leaf_values(level, rows, xy)
        centers = np.column_stack([xy, z])
        sizes = np.column_stack([edge, edge, np.zeros(len(edge))])
        return Cells(centers, sizes, value, occupied, level)

    def leaf_counts(self) -> NDArray[np.int64]:
        """Points in each leaf, in the order of :meth:`cells` (0 for unknown leaves)."""
        if self.square is None:
            return np.empty(0, np.int64)
        level, _keys, rows = self.stats.leaves()
        counts: NDArray[np.int64] = np.nan_to_num(self.leaf_stat(level, rows, "n")).astype(np.int64)
        return counts

    def leaf_stat(self, level: NDArray[np.int64], rows: NDArray[np.int64], what: str,
                  j: int = 0) -> NDArray[np.float64]:
        """Statistic ``what`` of value ``j`` for leaves (NaN for unknown leaves)."""
        out = np.full(len(rows), np.nan)
        for lev in np.unique(level):
            sel = (level == lev) & (rows >= 0)
            out[sel] = self.stats.column(int(lev), what, j)[rows[sel]]
        return out

    @property
    def basis_functions(self) -> int:
        """Number of leaves of the partition, known and unknown (all cells of f)."""
        return len(self.cells())

    @property
    def memory_bytes(self) -> int:
        """Bytes of the per-level key, statistics and split-flag arrays (and of the points
        a Quadtree build keeps)."""
        return self.stats.nbytes

    def corners(self) -> NDArray[np.float64]:
        """Corners of every known leaf at its height (M, 3), de-duplicated: set B of fig. 5.1.

        A 2D map's basis functions are heights: a free leaf is ground at its mean
        height, so it belongs to set B as much as an occupied one (the thesis builds B
        from "the corners of each basis function"); unknown leaves have no height.
        """
        cells = self.cells()
        return rectangle_corners(cells, np.isfinite(cells.centers[:, 2]))
