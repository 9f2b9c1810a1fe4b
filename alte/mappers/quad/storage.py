"""Where :class:`~alte.mappers.quad.levelstats.LevelStats` keeps its levels: arrays the OS
maps on first touch, and the per-level views its callers index."""

from __future__ import annotations

import mmap
from collections.abc import Iterator
from typing import Protocol

import numpy as np
from numpy.typing import DTypeLike

from alte.errors import MapperError

__all__ = ["Folding", "PerLevel", "lazy_zeros"]


class Folding(Protocol):
    """What a :class:`PerLevel` view asks of its statistics."""

    def fold(self, level: int) -> None:
        """Merge the level's deferred insertions."""

    def size(self, level: int) -> int:
        """Cells of the level."""
        ...


def lazy_zeros(shape: tuple[int, ...], dtype: DTypeLike) -> np.ndarray:
    """A zeroed array in anonymous memory that the OS maps 4 KiB at a time on first touch.

    numpy advises transparent huge pages for big arrays; then the first touch of every
    2 MiB zeroes (and may compact memory for) a whole huge page, a stall of milliseconds
    in whichever insertion meets it. Small pages spread that cost evenly."""
    count = int(np.prod(shape))
    buffer = mmap.mmap(-1, max(count * np.dtype(dtype).itemsize, 1))
    return np.frombuffer(buffer, dtype, count).reshape(shape)


class PerLevel:
    """``stats.keys``/``rows``/``split``: level ``l``'s sorted array (a view of its storage)."""

    def __init__(self, stats: Folding, store: list[np.ndarray]) -> None:
        self._stats, self._store = stats, store

    def __len__(self) -> int:
        return len(self._store)

    def __iter__(self) -> Iterator[np.ndarray]:
        return (self[level] for level in range(len(self)))

    def __getitem__(self, level: int) -> np.ndarray:
        self._stats.fold(level)
        return self._store[level][:self._stats.size(level)]

    def __setitem__(self, level: int, value: np.ndarray) -> None:
        view = self[level]
        if np.shape(value)[:1] != view.shape[:1]:
            raise MapperError(f"level {level}: {np.shape(value)[:1]} values for "
                              f"{len(view)} cells")
        view[...] = value
