"""The native Octomap's voxels: a float32 log-odds per observed voxel, in hashed blocks.

The map is, per finest (depth-16) voxel ever observed, a float32 log-odds, kept in
8x8x8 blocks found by hashing their Morton code. Memory therefore grows with the
observed volume, never with the bounding box; pruning and the ``.bt`` file
(``_octree``) work from the sorted voxels the store folds to.
"""

from __future__ import annotations

from collections.abc import MutableSequence, Sequence

import numba
import numpy as np
from numba.cpython.unsafe.numbers import trailing_zeros
from numpy.typing import NDArray

from alte.mappers.octomap.lanes import prefetch
from alte.mappers.octree.blockset import EMPTY, MORTON_BIT, WORDS, find_slot, rehash

__all__ = ["PAGE", "VoxelStore"]

#: Blocks per page of log-odds (2048 x 512 float32 = 4 MiB): the map grows a page at a
#: time, so no insert ever copies the map. numpy asks Linux for huge pages for arrays
#: from 4 MiB on, which halves the cost of a new page (fewer faults) and spares the
#: updates most TLB misses.
PAGE = 2048
_PAGE_SHIFT = 11


@numba.njit(cache=True)
def _add_pages(pages: MutableSequence[NDArray[np.float32]] | None, count: int,
               ) -> MutableSequence[NDArray[np.float32]]:
    """``pages`` (None: a new typed list) with ``count`` more pages of room for PAGE blocks
    each, untouched: a block's row is set to NaN when the block is made, so the cost of
    fresh memory is spread over the scans that add blocks. Compiled and cached: a typed
    list made or grown from Python compiles numba's own list functions in every process."""
    out = numba.typed.List.empty_list(numba.float32[:, ::1]) if pages is None else pages
    for _ in range(count):
        out.append(np.empty((PAGE, 512), dtype=np.float32))
    return out


class VoxelStore:
    """Per-voxel float32 log-odds in 8x8x8 blocks (NaN = never observed).

    A hash table maps a block's Morton code (key >> 9) to a row; rows live in
    fixed-size pages, so adding blocks never moves the map, and a scan's update
    (:func:`alte.mappers.octomap.scan.scan_blocks`) is applied block by block: one probe
    per block, one clamped float32 add per voxel, as OctoMap's ``updateNodeLogOdds``.
    Blocks of the observed volume are mostly full (75 % on sim_nav_1 at 0.2 m), so
    this takes less memory than a key and a value per voxel. :meth:`fold` gives the
    observed voxels as one sorted key array and their values.
    """

    def __init__(self) -> None:
        self._slots = np.full(1 << 10, EMPTY, dtype=np.uint64)
        self._rows = np.zeros(1 << 10, dtype=np.int64)
        self._blocks = np.zeros(PAGE, dtype=np.uint64)
        #: A numba typed list, so that the kernels take the pages as they are.
        self._pages = _add_pages(None, 1)
        self._page_count = 1
        self._n = 0
        self._folded: tuple[NDArray[np.uint64], NDArray[np.float32]] | None = None

    def __len__(self) -> int:
        """Observed voxels."""
        return int(self.fold()[0].size)

    @property
    def blocks(self) -> int:
        """Blocks in use."""
        return self._n

    @property
    def nbytes(self) -> int:
        """Bytes of the blocks in use (512 log-odds and a code each) and of the hash
        table; the unused rest of the last page is not counted."""
        return int(self._n * (512 * 4 + 8) + self._slots.nbytes + self._rows.nbytes)

    def _reserve(self, need: int) -> None:
        total = self._n + need
        more = -(-total // PAGE) - self._page_count
        if more > 0:
            self._pages = _add_pages(self._pages, more)
            self._page_count += more
        if total > self._blocks.size:
            grown = np.zeros(max(total, 2 * self._blocks.size), dtype=np.uint64)
            grown[:self._n] = self._blocks[:self._n]
            self._blocks = grown
        if 2 * total > self._slots.size:
            size = self._slots.size
            while 2 * total > size:
                size *= 2
            self._slots, self._rows = rehash(self._slots, self._blocks, self._n, size)

    def update(self, blocks: NDArray[np.uint64], bits: NDArray[np.uint64], miss: np.float32,
               hit: np.float32, clamp: tuple[np.float32, np.float32]) -> None:
        """Add ``miss`` at the free bits and ``hit`` at the occupied bits of each block
        (rows as :func:`~alte.mappers.octomap.scan.scan_blocks` gives), clamped; a new voxel
        starts at log-odds 0 (OctoMap's new node)."""
        if blocks.size == 0:
            return
        self._reserve(blocks.size)
        model = np.array([miss, hit, *clamp], dtype=np.float32)
        self._n = _apply((self._slots, self._rows, self._blocks), self._pages, self._n,
                         (blocks, bits), model)
        self._folded = None

    def fold(self) -> tuple[NDArray[np.uint64], NDArray[np.float32]]:
        """Sorted Morton keys of the observed voxels and their log-odds (cached until the
        next update)."""
        if self._folded is None:
            self._folded = _collect(self._blocks, self._pages, self._n)
        return self._folded


@numba.njit(cache=True)
def _page_order(rows: NDArray[np.int64], pages: int) -> NDArray[np.int64]:
    """Indices of ``rows`` grouped by page (a counting sort; order kept within a page)."""
    start = np.zeros(pages + 1, dtype=np.int64)
    for row in rows:
        start[(row >> _PAGE_SHIFT) + 1] += 1
    start = np.cumsum(start)
    order = np.empty(rows.size, dtype=np.int64)
    for r in range(rows.size):
        page = rows[r] >> _PAGE_SHIFT
        order[start[page]] = r
        start[page] += 1
    return order


@numba.njit(cache=True, inline="always")
def _block(values: NDArray[np.float32], bits: NDArray[np.uint64],
           model: NDArray[np.float32]) -> None:
    """Clamped add of miss at the free and hit at the occupied bits of one block (``model``
    is miss, hit, clamp low, clamp high)."""
    miss, hit, lo, hi = model[0], model[1], model[2], model[3]
    for w in range(2 * WORDS):
        word = bits[w]
        update = miss if w < WORDS else hit
        base = (w % WORDS) * 64
        while word:
            i = base + trailing_zeros(word)  # type: ignore[call-arg]  # numba intrinsic
            word &= word - np.uint64(1)
            value = values[i]
            if np.isnan(value):
                value = np.float32(0.0)
            values[i] = min(max(value + update, lo), hi)


@numba.njit(cache=True)
def _apply(store: tuple[NDArray[np.uint64], NDArray[np.int64], NDArray[np.uint64]],
           pages: Sequence[NDArray[np.float32]], n: int,
           scan: tuple[NDArray[np.uint64], NDArray[np.uint64]], model: NDArray[np.float32]) -> int:
    """Clamped float32 add of miss/hit at every set bit of the ``scan``'s blocks (codes,
    bit rows; new blocks get rows from ``n``); returns the new block count. ``store`` is
    the hash slots, their rows and the row blocks; ``model`` is miss, hit, clamp low,
    clamp high. Blocks are applied page by page, the next block's log-odds fetched while
    one is updated. (Arrays and tuples of arrays only: numba dispatches those fast.)"""
    slots, rows, blocks = store
    scan_blocks, scan_bits = scan
    at = np.empty(scan_blocks.size, dtype=np.int64)
    for r in range(scan_blocks.size):
        j = find_slot(slots, scan_blocks[r])
        if slots[j] == EMPTY:
            slots[j], rows[j], blocks[n] = scan_blocks[r], n, scan_blocks[r]
            pages[n >> _PAGE_SHIFT][n & (PAGE - 1)] = np.nan
            n += 1
        at[r] = rows[j]
    order = _page_order(at, len(pages))
    current, page = -1, pages[0]
    for q in range(order.size):
        row = at[order[q]]
        if row >> _PAGE_SHIFT != current:
            current, page = row >> _PAGE_SHIFT, pages[row >> _PAGE_SHIFT]
        if q + 1 < order.size and at[order[q + 1]] >> _PAGE_SHIFT == current:
            ahead = (at[order[q + 1]] & (PAGE - 1)) * 512
            for line in range(0, 512, 16):
                prefetch(page, ahead + line)  # type: ignore[call-arg, arg-type]  # numba intrinsic
        _block(page[row & (PAGE - 1)], scan_bits[order[q]], model)
    return n


@numba.njit(cache=True)
def _collect(blocks: NDArray[np.uint64], pages: Sequence[NDArray[np.float32]], n: int,
             ) -> tuple[NDArray[np.uint64], NDArray[np.float32]]:
    """Observed voxels in Morton order: blocks sorted, voxels by local Morton index within."""
    count = 0
    for row in range(n):
        count += 512 - np.isnan(pages[row >> _PAGE_SHIFT][row & (PAGE - 1)]).sum()
    keys = np.empty(count, dtype=np.uint64)
    values = np.empty(count, dtype=np.float32)
    k = 0
    for row in np.argsort(blocks[:n]):
        values_row = pages[row >> _PAGE_SHIFT][row & (PAGE - 1)]
        base = blocks[row] << np.uint64(9)
        for m in range(512):
            value = values_row[MORTON_BIT[m]]
            if not np.isnan(value):
                keys[k] = base | np.uint64(m)
                values[k] = value
                k += 1
    return keys, values
