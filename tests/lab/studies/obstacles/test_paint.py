"""The compiled raster paint of the obstacle scores against the numpy one it replaced."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from alte.lab.studies.landing.raster import RasterGeometry
from alte.lab.studies.obstacles.identify import _paint, _spans


def _numpy_paint(centers: NDArray[np.float64], half: NDArray[np.float64],
                 values: NDArray[np.float64], grid: RasterGeometry, centres: bool,
                 ) -> NDArray[np.float64]:
    """The paint as numpy array operations (the former implementation), the reference."""
    ny, nx = grid.shape
    out = np.full(ny * nx, -np.inf)
    c0, c1 = _spans(centers[:, 0] - half[:, 0], centers[:, 0] + half[:, 0], grid.origin[0],
                    grid.step, nx, centres=centres)
    r0, r1 = _spans(centers[:, 1] - half[:, 1], centers[:, 1] + half[:, 1], grid.origin[1],
                    grid.step, ny, centres=centres)
    width, rows = np.maximum(c1 - c0 + 1, 0), np.maximum(r1 - r0 + 1, 0)
    count = width * rows
    cell = np.repeat(np.arange(len(count)), count)
    k = np.arange(count.sum()) - np.repeat(np.cumsum(count) - count, count)
    flat = (r0[cell] + k // width[cell]) * nx + c0[cell] + k % width[cell]
    np.maximum.at(out, flat, values[cell])
    return np.where(np.isfinite(out), out, np.nan).reshape(grid.shape)


def test_the_compiled_paint_equals_the_numpy_one():
    """Random overlapping cells of many sizes, some off the raster, one NaN value: the
    same raster by pixel centres and by overlap."""
    rng = np.random.default_rng(5)
    grid = RasterGeometry((0.0, -1.0), 0.25, (40, 60))
    centers = np.column_stack([rng.uniform(-2, 17, 300), rng.uniform(-3, 11, 300),
                               rng.normal(0, 2, 300)])
    half = np.repeat(rng.choice([0.05, 0.125, 0.5, 2.0], 300)[:, None], 3, axis=1)
    values = centers[:, 2].copy()
    values[7] = np.nan
    for centres in (True, False):
        want = _numpy_paint(centers, half, values, grid, centres)
        got = _paint(centers, half, values, grid, centres)
        np.testing.assert_array_equal(got, want)
        assert np.isfinite(want).sum() > 500
