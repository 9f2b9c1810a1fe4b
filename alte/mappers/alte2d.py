"""2D-ALTE: adaptive piecewise-constant height map (thesis 3.3.1, eqs. 3.1-3.2).

``f(x, y) = sum_I c_I chi_I(x, y)`` with ``c_I`` the mean height of the points in
cell ``I``. A cell splits into four when it holds at least ``min_pts`` points, its
level is below ``max_res`` and its refinement criterion exceeds the threshold:

* ``criterion="thesis"`` (default), eq. 3.2: ``sum_{z in I} (z - c_I)^2 > tau`` with
  ``tau = kappa`` (m^2), the sum *not* normalised: a cell with many points splits
  on a small height spread, a sparse one needs a large spread, so refinement follows
  the data density, and flat ground stops at a few points x noise^2 / kappa. The sum
  of a parent is at least that of any child, so this top-down rule already gives
  the smallest tree holding every cell over the threshold. It depends on the cell
  alone, so an insertion recomputes split flags only where statistics changed;
  that locality (the thesis' real-time loop) and fidelity to the thesis make it the
  default. (A per-point variance ``> kappa`` was tried and rejected: a wide, mostly
  flat domain then never splits its root, hiding every obstacle.)
* ``criterion="binev"`` (Binev, Cohen, Dahmen, DeVore & Temlyakov 2005):
  ``eps_I = sum_J n_J (c_J - c_I)^2 / m`` over the four children ``J`` against
  ``tau_m = kappa * sqrt(log m / m)``, ``m`` the number of points in the map; as in
  that paper the tree is the smallest one holding every cell with ``eps_I > tau_m``
  (and ``min_pts`` points, below ``max_res``), so an ancestor splits when any
  descendant is marked even if its own children have similar means. ``m`` grows with
  every frame, so every flag is recomputed per insert (vectorized over the per-level
  statistics); the map after the last frame equals the batch map because leaves
  are always recomputed from the statistics.

Per cell and level the map keeps ``n``, the mean and ``M2`` of z (and max z), so
insertion costs O(new points x max_res). Cells without points are *unknown*:
height and value NaN, ``occupied`` False; known cells are "occupied" by the
height surface. :meth:`Alte2D.occupancy_grid` is the binary obstacle grid proposed
in thesis ch. 6 (mean height above a ground plane over a threshold).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import ClassVar, Literal, get_args

import numpy as np
from numpy.typing import NDArray

from alte.mappers.base import Cells, renamed
from alte.mappers.quad.quadmap import LeafValues, QuadMap, Rows, plane_height
from alte.params import Record, param

__all__ = ["Alte2D", "Alte2DSettings"]

Criterion = Literal["thesis", "binev"]
CRITERIA: tuple[str, ...] = get_args(Criterion)


@dataclass(frozen=True)
class Alte2DSettings(Record):
    """2D-ALTE parameters (module docstring)."""

    OWNER: ClassVar[str] = "alte2d"
    kappa: float = param(0.1, lambda v: v > 0, "kappa > 0",
                         "refinement threshold (m^2; see criterion)")
    max_res: int = param(6, lambda v: 0 <= v <= 20, "0 <= max_res <= 20",
                         "deepest level a cell may reach (root = 0)")
    min_pts: int = param(10, lambda v: v >= 1, "min_pts >= 1",
                         "fewest points a cell needs to split")
    criterion: Criterion = param("thesis", help="refinement criterion")


class Alte2D(QuadMap):
    """2D Adaptive Learning Terrain Estimation (see the module docstring)."""

    name: ClassVar[str] = "alte2d"
    title: ClassVar[str] = "2D-ALTE"
    Settings: ClassVar[type[Record]] = Alte2DSettings
    #: Contract v1's first name of :attr:`Settings` (deprecated; still read by old code).
    Params: ClassVar[type[Record]] = Alte2DSettings
    #: The cells' statistics do not depend on the split rule's thresholds, and neither
    #: does an insertion's work (the same touched cells get new flags).
    view_params: ClassVar[frozenset[str]] = frozenset({"kappa", "min_pts"})
    settings_grid: ClassVar[Mapping[str, tuple[object, ...]]] = {
        "max_res": (4, 5, 6, 7), "kappa": (0.01, 0.1, 1.0), "min_pts": (10,)}

    @property
    def depth(self) -> int:
        """``max_res``: the deepest level."""
        return int(self._params["max_res"])

    def _values(self, points: NDArray[np.float64]) -> NDArray[np.float64]:
        return points[:, 2:3]

    def _split(self, level: int, rows: Rows) -> NDArray[np.bool_]:
        """Thesis rule (eq. 3.2): ``M2 > kappa`` with enough points, below ``max_res``."""
        n = self.stats.column(level, "n")[rows]
        m2 = self.stats.column(level, "m2")[rows]
        split: NDArray[np.bool_] = ((n >= self._params["min_pts"]) & (level < self.depth)
                             & (m2 > self._params["kappa"]))
        return split

    def _update_splits(self, touched: list[NDArray[np.int64]] | None) -> None:
        if self._params["criterion"] == "thesis":
            super()._update_splits(touched)
            return
        tau = self._binev_tau()
        for level in range(self.depth, -1, -1):  # bottom-up: ancestors of marked cells split
            keys = self.stats.keys[level]
            n = self.stats.column(level, "n")
            marked = (n >= self._params["min_pts"]) & (level < self.depth)
            marked &= self._binev_indicator(level, np.arange(len(keys))) > tau
            if level < self.depth:
                below = self.stats.keys[level + 1][self.stats.split[level + 1]] >> 2
                marked[np.searchsorted(keys, below)] = True
            self.stats.split[level] = marked

    def _binev_tau(self) -> float:
        m = float(self.stats.column(0, "n").sum())
        return self._params["kappa"] * np.sqrt(np.log(m) / m) if m > 0 else 0.0

    def _binev_indicator(self, level: int, rows: NDArray[np.int64]) -> NDArray[np.float64]:
        """``sum_J n_J (c_J - c_I)^2 / m`` for the cells ``rows`` of ``level``."""
        out = np.zeros(len(rows))
        if level >= self.depth or not len(rows):
            return out
        m = float(self.stats.column(0, "n").sum())
        child_keys = self.stats.keys[level + 1]
        parent_pos = np.searchsorted(self.stats.keys[level], child_keys >> 2)
        c_parent = self.stats.column(level, "mean")[parent_pos]
        dev = self.stats.column(level + 1, "mean") - c_parent
        terms = self.stats.column(level + 1, "n") * dev * dev
        per_parent = np.bincount(parent_pos, terms, minlength=len(self.stats.keys[level]))
        share: NDArray[np.float64] = per_parent[rows] / m
        return share

    def _leaf_values(self, level: NDArray[np.int64], rows: NDArray[np.int64],
                     centers: NDArray[np.float64]) -> LeafValues:
        c = self.leaf_stat(level, rows, "mean")
        return c, c, rows >= 0

    def occupancy_grid(self, height_threshold: float,
                       ground: float | NDArray[np.float64] = 0.0) -> Cells:
        """Binary grid (thesis ch. 6): occupied where ``c_I`` rises over ``height_threshold``
        above ``ground`` (a z value or a plane ``a,b,c,d``); ``value`` = height above ground,
        NaN and free for unknown cells."""
        cells = self.cells()
        above = cells.centers[:, 2] - plane_height(ground, cells.centers[:, :2])
        occupied = np.isfinite(above) & (above > height_threshold)
        return Cells(cells.centers, cells.sizes, above, occupied, cells.level)


def __getattr__(name: str) -> object:
    """``Alte2DParams``: the first name of :class:`Alte2DSettings` (deprecated)."""
    return renamed(__name__, name, {"Alte2DParams": lambda: Alte2DSettings})
