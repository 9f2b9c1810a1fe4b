"""A 2D map on a fine regular raster, and local plane fits over it.

Landing tests need the same question answered at every candidate centre ("is the
disk around here known, planar, free?"), which is cheap on a regular grid with
image filters. :func:`rasterise` samples a map's cells at the pixel centres (each
pixel takes the height of the cell holding it; NaN where no cell with a height
does: unknown), :func:`rasterise_sigma` the height standard deviation of a map whose
cells carry a ``variance`` layer. :func:`plane_features` (the local plane fit of the
landing criterion) lives in :mod:`alte.ground.surface`, shared with the map export.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from alte.errors import ParameterError
from alte.ground.surface import PlaneFeatures, pixel_centres, plane_features
from alte.mappers.base import VARIANCE, Cells
from alte.metrics import cell_at_xy

__all__ = ["PlaneFeatures", "RasterGeometry", "plane_features", "rasterise", "rasterise_sigma"]


@dataclass(frozen=True)
class RasterGeometry:
    """A raster: lower-left corner ``origin`` (x, y), pixel ``step`` (m), ``shape`` (ny, nx)."""

    origin: tuple[float, float]
    step: float
    shape: tuple[int, int]

    @classmethod
    def from_bounds(cls, bounds: NDArray[np.float64], step: float) -> RasterGeometry:
        """The grid of ``step`` pixels covering ``bounds`` ((2, 2) or (2, 3): min/max corner)."""
        box = np.asarray(bounds, dtype=np.float64)
        if box.ndim != 2 or box.shape[0] != 2 or box.shape[1] < 2:
            raise ParameterError(f"landing grid: bounds must be (2, 2) or (2, 3), got {box.shape}")
        if not np.isfinite(step) or step <= 0:
            raise ParameterError(f"landing grid: step={step!r} must be > 0")
        size = box[1, :2] - box[0, :2]
        if not np.all(np.isfinite(size)) or np.any(size < step):
            raise ParameterError(f"landing grid: bounds {box[:, :2].tolist()} are smaller than "
                                 f"one {step} m pixel")
        nx, ny = np.floor(size / step + 1e-9).astype(int)
        return cls((float(box[0, 0]), float(box[0, 1])), float(step), (int(ny), int(nx)))

    def axes(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Pixel-centre x (nx,) and y (ny,) coordinates."""
        ny, nx = self.shape
        return (self.origin[0] + (np.arange(nx, dtype=np.float64) + 0.5) * self.step,
                self.origin[1] + (np.arange(ny, dtype=np.float64) + 0.5) * self.step)

    def centers(self) -> NDArray[np.float64]:
        """Pixel centres (ny * nx, 2), row-major (y slow, x fast)."""
        return pixel_centres(self.origin, self.step, self.shape)

    def index(self, xy: NDArray[np.float64]) -> NDArray[np.int64]:
        """(row, col) of the pixels holding points ``xy`` (N, 2) (not clipped)."""
        rc = np.floor((np.asarray(xy, dtype=np.float64) - self.origin) / self.step)
        return rc[:, ::-1].astype(np.int64)

    @property
    def extent(self) -> tuple[float, float, float, float]:
        """(xmin, xmax, ymin, ymax), matplotlib's ``imshow`` extent."""
        ny, nx = self.shape
        x0, y0 = self.origin
        return (x0, x0 + nx * self.step, y0, y0 + ny * self.step)


def _sample(cells: Cells, grid: RasterGeometry, values: NDArray[np.float64]) -> NDArray[np.float64]:
    """``values`` (one per cell) of the known cell holding each pixel centre; NaN elsewhere."""
    known = np.isfinite(cells.centers[:, 2])
    idx = cell_at_xy(grid.centers(), cells.centers[known], cells.sizes[known])
    mine = values[known]
    out = np.where(idx >= 0, mine[np.maximum(idx, 0)] if len(mine) else np.nan, np.nan)
    return out.reshape(grid.shape)


def rasterise(cells: Cells, grid: RasterGeometry) -> NDArray[np.float64]:
    """Height (ny, nx) of the cell holding each pixel centre; NaN where unknown."""
    return _sample(cells, grid, cells.centers[:, 2])


def rasterise_sigma(cells: Cells, grid: RasterGeometry) -> NDArray[np.float64]:
    """Height standard deviation (ny, nx) of the cell holding each pixel centre (the square
    root of its ``variance`` layer); NaN where unknown. A map without the layer raises."""
    variance = cells.layer(VARIANCE)
    if variance is None:
        raise ParameterError("landing: the map's cells carry no height variance")
    return _sample(cells, grid, np.sqrt(np.maximum(np.asarray(variance, np.float64), 0.0)))
