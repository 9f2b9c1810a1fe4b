"""A 2D map on a fine regular raster, and local plane fits over it.

Landing tests need the same question answered at every candidate centre ("is the
disk around here known, planar, free?"), which is cheap on a regular grid with
image filters. :func:`rasterise` samples a map's cells at the pixel centres (each
pixel takes the height of the cell holding it; NaN where no cell with a height
does: unknown). :func:`plane_features` fits ``z = a x + b y + c`` by least squares
over a square window around every pixel at once: the window sums of the moments
``1, x, y, z, x^2, xy, y^2, xz, yz, z^2`` of the known pixels come from
``scipy.ndimage.uniform_filter``, so the fit costs ten filters whatever the window.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from alte.errors import ParameterError
from alte.mappers.base import Cells
from alte.metrics import cell_at_xy

__all__ = ["Grid", "PlaneFeatures", "plane_features", "rasterise"]


@dataclass(frozen=True)
class Grid:
    """A raster: lower-left corner ``origin`` (x, y), pixel ``step`` (m), ``shape`` (ny, nx)."""

    origin: tuple[float, float]
    step: float
    shape: tuple[int, int]

    @classmethod
    def from_bounds(cls, bounds: np.ndarray, step: float) -> Grid:
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

    def axes(self) -> tuple[np.ndarray, np.ndarray]:
        """Pixel-centre x (nx,) and y (ny,) coordinates."""
        ny, nx = self.shape
        return (self.origin[0] + (np.arange(nx) + 0.5) * self.step,
                self.origin[1] + (np.arange(ny) + 0.5) * self.step)

    def centers(self) -> np.ndarray:
        """Pixel centres (ny * nx, 2), row-major (y slow, x fast)."""
        xs, ys = self.axes()
        gx, gy = np.meshgrid(xs, ys, indexing="xy")
        return np.column_stack([gx.ravel(), gy.ravel()])

    def index(self, xy: np.ndarray) -> np.ndarray:
        """(row, col) of the pixels holding points ``xy`` (N, 2) (not clipped)."""
        rc = np.floor((np.asarray(xy, dtype=np.float64) - self.origin) / self.step)
        return rc[:, ::-1].astype(np.int64)

    @property
    def extent(self) -> tuple[float, float, float, float]:
        """(xmin, xmax, ymin, ymax), matplotlib's ``imshow`` extent."""
        ny, nx = self.shape
        x0, y0 = self.origin
        return (x0, x0 + nx * self.step, y0, y0 + ny * self.step)


def rasterise(cells: Cells, grid: Grid) -> np.ndarray:
    """Height (ny, nx) of the cell holding each pixel centre; NaN where unknown."""
    known = np.isfinite(cells.centers[:, 2])
    centers, sizes = cells.centers[known], cells.sizes[known]
    idx = cell_at_xy(grid.centers(), centers, sizes)
    height = np.where(idx >= 0, centers[np.maximum(idx, 0), 2] if len(centers) else np.nan,
                      np.nan)
    return height.reshape(grid.shape)


@dataclass(frozen=True)
class PlaneFeatures:
    """Per pixel: plane tilt ``slope_deg``, residual std ``roughness`` (m), known ``count``.

    NaN where the window's known pixels do not fix a plane (fewer than 3, collinear).
    """

    slope_deg: np.ndarray
    roughness: np.ndarray
    count: np.ndarray


def plane_features(height: np.ndarray, step: float, radius: float) -> PlaneFeatures:
    """Least-squares plane over the square window of half-side ``radius`` (m) at every pixel."""
    known = np.isfinite(height)
    half = max(int(np.ceil(radius / step - 1e-9)), 1)
    size = 2 * half + 1
    ny, nx = height.shape
    y, x = np.meshgrid((np.arange(ny) - ny / 2) * step, (np.arange(nx) - nx / 2) * step,
                       indexing="ij")
    w = known.astype(np.float64)
    z = np.where(known, height - np.median(height[known]), 0.0) if known.any() else w

    def mean(values: np.ndarray) -> np.ndarray:
        return ndimage.uniform_filter(values * w, size=size, mode="constant", cval=0.0)

    s1 = mean(np.ones_like(z))
    with np.errstate(invalid="ignore", divide="ignore"):
        mx, my, mz = mean(x) / s1, mean(y) / s1, mean(z) / s1
        cxx = mean(x * x) / s1 - mx * mx
        cyy = mean(y * y) / s1 - my * my
        cxy = mean(x * y) / s1 - mx * my
        cxz = mean(x * z) / s1 - mx * mz
        cyz = mean(y * z) / s1 - my * mz
        czz = mean(z * z) / s1 - mz * mz
        det = cxx * cyy - cxy * cxy
        ok = (s1 * size * size >= 2.5) & (det > 1e-6 * step**4)
        a = np.where(ok, (cyy * cxz - cxy * cyz) / det, np.nan)
        b = np.where(ok, (cxx * cyz - cxy * cxz) / det, np.nan)
        residual = np.maximum(czz - a * cxz - b * cyz, 0.0)
    slope = np.degrees(np.arctan(np.hypot(a, b)))
    return PlaneFeatures(slope, np.sqrt(residual), np.rint(s1 * size * size).astype(np.int64))
