"""Checks on map cells shared by the mapper tests: partitions and cell-for-cell equality."""

from __future__ import annotations

import numpy as np

from alte.mappers.base import Cells

__all__ = ["assert_partition", "same_cells"]


def assert_partition(cells: Cells, size: float = 16.0) -> None:
    """Leaves cover the square [0, size]^2 exactly once: areas add up, probes hit one cell each."""
    assert np.isclose((cells.sizes[:, 0] * cells.sizes[:, 1]).sum(), size * size)
    probes = np.random.default_rng(1).uniform(0, size, (200, 2))
    lo = cells.centers[:, :2] - cells.sizes[:, :2] / 2
    hi = cells.centers[:, :2] + cells.sizes[:, :2] / 2
    inside = ((probes[:, None] >= lo) & (probes[:, None] < hi)).all(axis=2)
    assert (inside.sum(axis=1) == 1).all()


def same_cells(a: Cells, b: Cells, values: bool = True) -> bool:
    """Same leaves (levels, centres, occupancy and, with ``values``, values; NaN equal NaN)."""
    return (len(a) == len(b) and np.array_equal(a.level, b.level)
            and np.allclose(a.centers, b.centers, equal_nan=True)
            and (not values or np.allclose(a.value, b.value, equal_nan=True))
            and np.array_equal(a.occupied, b.occupied))
