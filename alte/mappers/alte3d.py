"""3D-ALTE (thesis 3.3.2): adaptive octree of occupied / unoccupied cubes over a fixed domain.

A cell splits into eight while it holds more than ``min_pts_split`` points and its
level is below ``max_res``. The map state is one sparse table of point counts per
level (sorted integer cell keys + int64 counts), so ``insert`` costs
O(new points * max_res) plus a merge, and the leaves are derived from the counts:
inserting frame by frame equals building once, exactly (counts are integers).

Occupancy (thesis 5.2.2 adds a level-aware check; this is OUR rule, stated here):
a leaf at level ``l`` is occupied when it holds at least
``min_pts * k ** max(0, occupancy_level - l)`` points, ``k`` = 8 children per split
(4 for ``fixed_altitude``). ``min_pts`` is the threshold for a cell at
``occupancy_level`` (default 6, the thesis' max_res); a coarser cell must hold the
same point density per volume. Thus a coarse cell that stopped splitting for lack
of points (<= ``min_pts_split``) is never a huge occupied box, and a coarse
``max_res`` (4) leaves sparsely sampled surfaces unoccupied: the incomplete map the
thesis reports. ``occupancy_level=0`` gives the plain count rule.

``variant=fixed_altitude`` is figure 3.16's map: cells split only in x, y and the
z axis is cut into layers of ``cell_height`` metres from the domain's zmin.
"""

from __future__ import annotations

import copy
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import ClassVar, Literal

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
    renamed,
)
from alte.mappers.domain import Domain, DomainUse, check_domain
from alte.mappers.octree.celltable import (
    KEY_MASK,
    Z_OFFSET,
    child_keys,
    merge_counts,
    pack_keys,
    unpack_keys,
)
from alte.mappers.octree.tree import check_origin
from alte.params import Record, param
from alte.types import Box

__all__ = ["Alte3D", "Alte3DSettings"]




@dataclass(frozen=True)
class Alte3DSettings(Record):
    """3D-ALTE parameters (module docstring)."""

    OWNER: ClassVar[str] = "alte3d"
    max_res: int = param(6, lambda v: 0 <= v <= 16, "0 <= max_res <= 16", "maximum splits")
    min_pts: int = param(10, lambda v: v >= 1, ">= 1", "points to be occupied (MIN PTS)")
    min_pts_split: int = param(20, lambda v: v >= 1, ">= 1", "split above (MIN PTS 2)")
    occupancy_level: int = param(6, lambda v: 0 <= v <= 16, "0 <= level <= 16",
                                 "level at which min_pts applies; coarser cells scale it")
    variant: Literal["cube", "fixed_altitude"] = param(
        "cube", help="cubes, or x/y cells in cell_height layers")
    cell_height: float = param(1.0, lambda v: v > 0, "> 0", "layer height (fixed_altitude)")


class Alte3D:
    """3D-ALTE map; ``basis_functions`` = all leaves of the adaptive partition.

    Occupied and unoccupied leaves both count (including the empty children of a
    split): a planner walking the partition handles every cell, as Octomap's count
    includes its free leaves. ``domain`` must be given for ``insert`` (the partition is
    anchored on it); ``build`` uses the bounding cube of the data when there is none.
    Points outside the domain are dropped and counted (:attr:`points_outside`).
    """

    api_version: ClassVar[int] = API_VERSION
    name: ClassVar[str] = "alte3d"
    title: ClassVar[str] = "3D-ALTE"
    dims: ClassVar[int] = 3
    incremental: ClassVar[bool] = True
    domain_use: ClassVar[DomainUse] = DomainUse.REQUIRED
    default_feed: ClassVar[Feed] = Feed.FRAMES
    exports: ClassVar[frozenset[str]] = frozenset({".npz"})
    free_space: ClassVar[bool] = False
    #: Splits and occupancy are read off the per-level counts, which depend on
    #: ``max_res`` (and the variant) only.
    view_params: ClassVar[frozenset[str]] = frozenset({"min_pts", "min_pts_split",
                                                       "occupancy_level"})
    cost_unit: ClassVar[Cost] = Cost.CELL_UPDATES
    layers: ClassVar[frozenset[str]] = frozenset()
    settings_grid: ClassVar[Mapping[str, tuple[object, ...]]] = {
        "max_res": (4, 5, 6, 7, 8), "min_pts_split": (10, 40), "min_pts": (5, 20)}
    Settings: ClassVar[type[Record]] = Alte3DSettings
    #: Contract v1's first name of :attr:`Settings` (deprecated; still read by old code).
    Params: ClassVar[type[Record]] = Alte3DSettings

    def __init__(self, domain: Domain | None = None, *, record: Record | None = None,
                 **given: object) -> None:
        domain = check_domain("alte3d", domain)
        self._record = parsed(Alte3DSettings, record, given)
        self._params = self._record.as_dict()
        self._fixed = domain
        self._domain = domain
        self.points_outside = 0
        self._reset()

    def _reset(self) -> None:
        levels = self._params["max_res"] + 1
        self._keys = [np.empty(0, dtype=np.int64) for _ in range(levels)]
        self._counts = [np.empty(0, dtype=np.int64) for _ in range(levels)]
        self._cells: Cells | None = None  # the leaves, until the next insert or build
        self._shared = False  # the count tables are shared with a re-read copy
        self._cost = 0

    @property
    def params(self) -> Record:
        """The validated parameters, defaults filled in."""
        return self._record

    @property
    def domain(self) -> Domain | None:
        """The root cube, or None before the first build without a given domain."""
        return self._domain

    def write_native(self, path: Path, overwrite: bool = False) -> Path:
        """3D-ALTE has no format of its own: export ``.npz`` cells instead."""
        raise MapperError("alte3d: no native map format; export .npz instead")

    @property
    def _branching(self) -> int:
        return 4 if self._params["variant"] == "fixed_altitude" else 8

    def insert(self, points: NDArray[np.float64], origin: NDArray[np.float64]) -> None:
        """Add one frame's points (``origin`` is checked but 3D-ALTE does not use it)."""
        pts = check_points(points, "alte3d")
        check_origin(origin, "alte3d")
        if self._domain is None:
            raise MapperError("alte3d: insert needs a fixed domain (the partition is anchored "
                              "on it); give one, or use build, which takes the data's cube")
        self._add(pts)

    def build(self, points: NDArray[np.float64],
              origins: NDArray[np.float64] | None = None) -> None:
        """Rebuild from a whole cloud (``origins`` unused)."""
        pts = check_points(points, "alte3d")
        if self._fixed is None:
            if pts.shape[0] == 0:
                raise MapperError("alte3d: cannot build from an empty cloud without a domain")
            self._domain = Domain.over(Box.around(pts))
        self._reset()
        self.points_outside = 0
        self._add(pts)

    def reread(self, **changes: object) -> Alte3D:
        """This map read with other ``min_pts``, ``min_pts_split``, ``occupancy_level``
        (:meth:`alte.mappers.base.Mapper.reread`)."""
        check_view(self, changes)
        record = self._record.replace(**changes)
        other = copy.copy(self)
        other._record, other._params, other._cells = record, record.as_dict(), None
        self._shared = other._shared = True
        return other

    def _add(self, pts: NDArray[np.float64]) -> None:
        if self._shared:
            raise MapperError("alte3d: this map was re-read with other parameters and shares "
                              "its counts with the copy; build it afresh to add points")
        self._cells = None
        finest = self._finest_keys(pts)
        if finest.size == 0:
            return
        max_res = self._params["max_res"]
        self._cost += finest.size
        for level in range(max_res + 1):
            keys, counts = np.unique(self._at_level(finest, max_res - level), return_counts=True)
            self._cost += keys.size
            self._keys[level], self._counts[level] = merge_counts(
                self._keys[level], self._counts[level], keys, counts
            )

    def _finest_keys(self, pts: NDArray[np.float64]) -> NDArray[np.int64]:
        """Packed cell keys at level max_res; points outside the domain are dropped, counted."""
        dom = self._domain
        assert dom is not None  # insert and build set the domain first
        n = 1 << self._params["max_res"]
        axes = 2 if self._params["variant"] == "fixed_altitude" else 3
        inside = dom.inside(pts, axes)
        if axes == 2:
            layer = np.floor((pts[:, 2] - dom.zmin) / self._params["cell_height"]) + Z_OFFSET
            inside &= (layer >= 0) & (layer <= KEY_MASK)
        self.points_outside += int(inside.size - np.count_nonzero(inside))
        pts = pts[inside]
        idx = np.minimum(((pts - dom.lo) / dom.size * n).astype(np.int64), n - 1)
        if axes == 2:
            idx[:, 2] = layer[inside]
        return pack_keys(idx[:, 0], idx[:, 1], idx[:, 2])

    def _at_level(self, finest: NDArray[np.int64], shift: int) -> NDArray[np.int64]:
        ix, iy, iz = unpack_keys(finest)
        if self._params["variant"] == "cube":
            iz = iz >> shift
        return pack_keys(ix >> shift, iy >> shift, iz)

    def _count(self, level: int, keys: NDArray[np.int64]) -> NDArray[np.int64]:
        """Point counts of ``keys`` at ``level`` (0 for cells never seen)."""
        table, counts = self._keys[level], self._counts[level]
        if table.size == 0:
            return np.zeros(keys.size, dtype=np.int64)
        pos = np.minimum(np.searchsorted(table, keys), table.size - 1)
        return np.where(table[pos] == keys, counts[pos], 0)

    def _leaves(self) -> tuple[list[NDArray[np.int64]], list[NDArray[np.int64]]]:
        """Leaf keys and counts per level, walking down from the root(s) through split cells."""
        p = self._params
        leaves, counts = [], []
        cells = self._keys[0] if p["variant"] == "fixed_altitude" else np.zeros(1, np.int64)
        for level in range(p["max_res"] + 1):
            n = self._count(level, cells)
            split = (n > p["min_pts_split"]) & (level < p["max_res"])
            leaves.append(cells[~split])
            counts.append(n[~split])
            cells = child_keys(cells[split], p["variant"])
        return leaves, counts

    def cell_counts(self) -> CellCounts:
        """Counts of :meth:`cells` (small maps: the table itself)."""
        return CellCounts.of(self.cells())

    def cells(self) -> Cells:
        """Leaves: centre, size, point count, occupied flag and level (derived from the
        counts once per state of the map)."""
        if self._cells is None:
            self._cells = self._make_cells()
        return self._cells

    def _make_cells(self) -> Cells:
        if self._domain is None:
            empty = np.empty((0, 3))
            return Cells(empty, empty, np.empty(0), np.empty(0, bool), np.empty(0, np.int64))
        keys, counts = self._leaves()
        los, his = zip(*(self._bounds(k, lv) for lv, k in enumerate(keys)), strict=True)
        lo, hi = np.concatenate(los), np.concatenate(his)
        level = np.concatenate([np.full(k.size, lv) for lv, k in enumerate(keys)])
        value = np.concatenate(counts)
        need = self._params["min_pts"] * self._branching ** np.maximum(
            0, self._params["occupancy_level"] - level)
        return Cells((lo + hi) / 2, hi - lo, value.astype(np.float64), value >= need, level)

    def _bounds(self, keys: NDArray[np.int64], level: int,
                ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        assert self._domain is not None  # cells() returns early without one
        xmin, ymin, zmin, size = (self._domain.xmin, self._domain.ymin, self._domain.zmin,
                                  self._domain.size)
        edge = size / (1 << level)
        ix, iy, iz = unpack_keys(keys)
        lo = np.c_[xmin + ix * edge, ymin + iy * edge, zmin + iz * edge]
        hi = lo + edge
        if self._params["variant"] == "fixed_altitude":
            lo[:, 2] = zmin + (iz - Z_OFFSET) * self._params["cell_height"]
            hi[:, 2] = lo[:, 2] + self._params["cell_height"]
        return lo, hi

    @property
    def basis_functions(self) -> int:
        return len(self.cells())

    @property
    def cost(self) -> int:
        """Points located plus cell counts written on every level (:class:`Cost`)."""
        return self._cost

    @property
    def memory_bytes(self) -> int:
        return int(sum(k.nbytes + c.nbytes for k, c in zip(self._keys, self._counts, strict=True)))

    def corners(self) -> NDArray[np.float64]:
        """The 8 corners of every occupied leaf, de-duplicated."""
        cells = self.cells()
        lo = cells.centers[cells.occupied] - cells.sizes[cells.occupied] / 2
        size = cells.sizes[cells.occupied]
        offsets = np.array([[i >> 2 & 1, i >> 1 & 1, i & 1] for i in range(8)], dtype=np.float64)
        corners = (lo[:, None, :] + offsets[None] * size[:, None, :]).reshape(-1, 3)
        return unique_rows(corners)


def __getattr__(name: str) -> object:
    """``Alte3DParams``: the first name of :class:`Alte3DSettings` (deprecated)."""
    return renamed(__name__, name, {"Alte3DParams": lambda: Alte3DSettings})
