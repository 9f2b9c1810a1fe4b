"""The elevation map: a regular 2.5D grid whose cells say how sure they are of their height.

In the style of ETH's ``elevation_mapping`` (Fankhauser, Bloesch, Gehring, Hutter &
Siegwart, "Robot-centric elevation mapping with uncertainty estimates", CLAWAR 2014) and
``elevation_mapping_cupy``, written against alte's public mapper contract only
(:mod:`alte.mappers.api`): every cell of ``resolution`` metres fuses the heights of the
points falling in it with a 1-D Kalman update (:mod:`alte_elevation.fusion`), each point
weighed by its range- and angle-dependent noise (:mod:`alte_elevation.noise`).

The grid is sparse: only cells some point fell in are stored (sorted int64 keys), so a
fine grid over a wide terrain costs what its points cost. Its corner is the domain's
when one is given, else the origin of the coordinates.

``cells()`` gives every stored cell at its fused height, with the layers ``variance``
(the height variance, m^2), ``min`` and ``max`` (lowest and highest point, m) and
``count`` (points). How the stored state is read (the view parameters, so a sweep
over them shares one map):

* ``min_variance`` floors the variance (``elevation_mapping``'s default, (3 mm)^2);
* a cell whose variance exceeds ``max_variance`` is *unknown* (NaN height), as
  ``elevation_mapping`` invalidates it; its default here, (0.5 m)^2, is ours:
  ``elevation_mapping``'s (3 cm)^2 suits a legged robot's sensor a metre or two from the
  ground, where a UAV's single point at 20 m carries more noise than that;
* ``spread`` adds to the variance the spread of the heights of the cell's points beyond
  their noise (:meth:`~alte_elevation.fusion.CellState.spread`): the Kalman variance alone is
  the uncertainty of the mean of the points, which shrinks with every point, while the
  terrain inside a cell (a slope, an edge) differs from that mean wherever one lands.

Every known cell is ``occupied`` (the cell is part of the surface, as 2D-ALTE's are); the
landing study and the obstacle scores read obstacles off the heights.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numpy.typing import NDArray

from alte.mappers.api import VARIANCE, Cells, MapperBase, Record, param
from alte_elevation.fusion import CellState, Gate, fuse
from alte_elevation.noise import point_variance

__all__ = ["LAYERS", "ElevationMap", "ElevationSettings"]

#: The per-cell layers of :meth:`ElevationMap.cells`.
LAYERS = frozenset({VARIANCE, "min", "max", "count"})
#: Cell indices are offset by this (a key packs two 32-bit fields; the sign bit stays 0).
_OFFSET = np.int64(1 << 30)


def _positive(value: float) -> bool:
    return bool(np.isfinite(value) and value > 0)


def _non_negative(value: float) -> bool:
    return bool(np.isfinite(value) and value >= 0)


@dataclass(frozen=True)
class ElevationSettings(Record):
    """Elevation map parameters (module docstring; the noise model's in
    :mod:`alte_elevation.noise`)."""

    OWNER: ClassVar[str] = "elevation"
    resolution: float = param(0.5, _positive, "resolution > 0", "cell edge (m)")
    range_sigma: float = param(0.03, _positive, "range_sigma > 0",
                               "point noise along the beam (m; VLP-16 data sheet: 3 cm)")
    beam_constant: float = param(0.0015, _non_negative, "beam_constant >= 0",
                                 "point noise across the beam at the sensor (m)")
    beam_angle: float = param(0.0006, _non_negative, "beam_angle >= 0",
                              "growth of the noise across the beam per metre of range")
    mahalanobis: float = param(2.5, _positive, "mahalanobis > 0",
                               "gate: sigmas of the innovation a point may lie off the cell")
    multi_height_noise: float = param(0.003**2, _non_negative, "multi_height_noise >= 0",
                                      "variance added to a cell per point the gate rejects "
                                      "(m^2)")
    min_variance: float = param(0.003**2, _non_negative, "min_variance >= 0",
                                "floor of a cell's variance (m^2)")
    max_variance: float = param(0.5**2, _positive, "max_variance > 0",
                                "a cell less sure than this is unknown (m^2)")
    spread: bool = param(True, help="add the spread of a cell's heights beyond their noise "
                                    "to its variance")


class ElevationMap(MapperBase[ElevationSettings]):
    """A 2.5D grid of Kalman-fused heights with per-cell variance (module docstring)."""

    name: ClassVar[str] = "elevation"
    title: ClassVar[str] = "Elevation map"
    dims: ClassVar[int] = 2
    Settings: ClassVar[type[Record]] = ElevationSettings
    view_params: ClassVar[frozenset[str]] = frozenset({"min_variance", "max_variance",
                                                       "spread"})
    layers: ClassVar[frozenset[str]] = LAYERS
    settings_grid: ClassVar[Mapping[str, tuple[object, ...]]] = {
        "resolution": (0.05, 0.1, 0.2, 0.5, 1.0, 2.0)}

    def clear(self) -> None:
        """No cell."""
        self._state = CellState.empty()

    @property
    def corner(self) -> NDArray[np.float64]:
        """The grid's corner (x, y): the domain's, else the origin."""
        return (np.zeros(2) if self.domain is None
                else np.array([self.domain.xmin, self.domain.ymin]))

    def _keys(self, xy: NDArray[np.float64]) -> NDArray[np.int64]:
        ij = np.floor((xy - self.corner) / self.params.resolution).astype(np.int64) + _OFFSET
        return (ij[:, 0] << np.int64(32)) | ij[:, 1]

    def _insert(self, points: NDArray[np.float64], origins: NDArray[np.float64] | None) -> None:
        p = self.params
        r = point_variance(points, origins, p.range_sigma, p.beam_constant, p.beam_angle)
        gate = Gate(p.mahalanobis, p.multi_height_noise)
        self._state = fuse(self._state, self._keys(points[:, :2]), points[:, 2], r, gate)

    def cells(self) -> Cells:
        """Every stored cell at its fused height, with the layers of :data:`LAYERS`."""
        s, p = self._state, self.params
        ij = np.column_stack([s.keys >> np.int64(32), s.keys & np.int64(0xFFFFFFFF)]) - _OFFSET
        variance = np.maximum(s.variance + (s.spread() if p.spread else 0.0), p.min_variance)
        known = variance <= p.max_variance
        height = np.where(known, s.height, np.nan)
        n = len(s)
        centers = np.column_stack([self.corner + (ij + 0.5) * p.resolution, height])
        sizes = np.tile([p.resolution, p.resolution, 0.0], (n, 1))
        layers = {VARIANCE: np.where(known, variance, np.nan), "min": s.low.copy(),
                  "max": s.high.copy(), "count": s.points.copy()}
        return Cells(centers, sizes, height.copy(), known, np.zeros(n, np.int64), layers)

    @property
    def memory_bytes(self) -> int:
        """Bytes of the cells' arrays."""
        return self._state.nbytes
