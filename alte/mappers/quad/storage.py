"""Where :class:`~alte.mappers.quad.levelstats.LevelStats` keeps its levels: arrays the OS
maps on first touch, and the per-level views its callers index."""

from __future__ import annotations

import mmap
from collections.abc import Iterator
from typing import Generic, Protocol, TypeVar

import numpy as np
from numpy.typing import NDArray

from alte.errors import MapperError

__all__ = ["Folding", "PerLevel", "lazy_zeros"]

#: What a level stores: int64 keys, float64 statistics, bool split flags, int32 dense index.
_S = TypeVar("_S", np.int64, np.float64, np.bool_, np.int32)


class Folding(Protocol):
    """What a :class:`PerLevel` view asks of its statistics."""

    def fold(self, level: int) -> None:
        """Merge the level's deferred insertions."""

    def size(self, level: int) -> int:
        """Cells of the level."""
        ...


def lazy_zeros(shape: tuple[int, ...], dtype: type[_S] | np.dtype[_S]) -> NDArray[_S]:
    """A zeroed array in anonymous memory that the OS maps 4 KiB at a time on first touch.

    numpy advises transparent huge pages for big arrays; then the first touch of every
    2 MiB zeroes (and may compact memory for) a whole huge page, a stall of milliseconds
    in whichever insertion meets it. Small pages spread that cost evenly."""
    count = int(np.prod(shape))
    buffer = mmap.mmap(-1, max(count * np.dtype(dtype).itemsize, 1))
    return np.frombuffer(buffer, dtype, count).reshape(shape)


class PerLevel(Generic[_S]):
    """``stats.keys``/``rows``/``split``: level ``l``'s sorted array (a view of its storage)."""

    def __init__(self, stats: Folding, store: list[NDArray[_S]]) -> None:
        self._stats = stats
        self._store: list[NDArray[_S]] = store

    def __len__(self) -> int:
        return len(self._store)

    def __iter__(self) -> Iterator[NDArray[_S]]:
        return (self[level] for level in range(len(self)))

    def __getitem__(self, level: int) -> NDArray[_S]:
        self._stats.fold(level)
        return self._store[level][:self._stats.size(level)]

    def __setitem__(self, level: int, value: NDArray[_S]) -> None:
        view = self[level]
        if np.shape(value)[:1] != view.shape[:1]:
            raise MapperError(f"level {level}: {np.shape(value)[:1]} values for "
                              f"{len(view)} cells")
        view[...] = value
