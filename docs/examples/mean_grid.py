"""A minimal alte mapper: each cell of a regular grid holds the mean height of its points."""

from collections.abc import Mapping
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numpy.typing import NDArray

from alte.mappers.api import Cells, MapperBase, Record, param


@dataclass(frozen=True)
class MeanGridSettings(Record):
    """The parameters ``--set`` and sweep specs give, validated on creation."""

    OWNER: ClassVar[str] = "meangrid"
    cell: float = param(1.0, lambda v: v > 0, "cell > 0", "cell edge (m)")


class MeanGrid(MapperBase[MeanGridSettings]):
    """A 2.5D grid of ``cell`` metres: a cell's height is the mean z of its points."""

    name = "meangrid"
    title = "Mean grid"
    dims = 2
    Settings = MeanGridSettings
    settings_grid: ClassVar[Mapping[str, tuple[object, ...]]] = {"cell": (0.25, 0.5, 1.0, 2.0)}

    def clear(self) -> None:
        self._keys = np.empty((0, 2), np.int64)
        self._sum, self._count = np.empty(0), np.empty(0)

    def _insert(self, points: NDArray[np.float64], origins: NDArray[np.float64] | None) -> None:
        keys = np.floor(points[:, :2] / self.params.cell).astype(np.int64)
        merged, where = np.unique(np.vstack([self._keys, keys]), axis=0, return_inverse=True)
        old, new, k = where[: len(self._keys)], where[len(self._keys):], len(merged)
        self._sum = np.bincount(old, self._sum, k) + np.bincount(new, points[:, 2], k)
        self._count = np.bincount(old, self._count, k) + np.bincount(new, minlength=k)
        self._keys = merged

    def cells(self) -> Cells:
        size, n = self.params.cell, len(self._keys)
        height = self._sum / self._count
        centers = np.column_stack([(self._keys + 0.5) * size, height])
        return Cells(centers, np.tile([size, size, 0.0], (n, 1)), height,
                     np.ones(n, bool), np.zeros(n, np.int64))
