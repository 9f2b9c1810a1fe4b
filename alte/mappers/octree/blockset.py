"""Sets of voxel keys as 8x8x8 bit blocks: the per-scan key set of the native Octomap.

A block is named by its Morton code (key >> 9) and holds 16 words: 8 of *free* bits,
then 8 of *occupied* bits, bit ``x + 8 y + 64 z`` of the 512 being the voxel whose
per-axis key ends in (x, y, z) (:func:`local_index`), so each byte is an x row: the
layout of the flat grid a scan's rays are walked in. An open-addressing hash table
maps a block code to its row.
A table is the tuple ``(slots, rows, bits, blocks)``; rows are added in arrival order.
"""

from __future__ import annotations

import numba
import numpy as np
from numpy.typing import NDArray

#: A block set: hash slots, their rows, bit rows (free, occupied) and block ids.
Table = tuple[NDArray[np.uint64], NDArray[np.int64], NDArray[np.uint64], NDArray[np.uint64]]

__all__ = ["EMPTY", "MORTON_BIT", "WORDS", "find_slot", "keys_to_blocks", "local_index",
           "new_table", "rehash", "reserve", "row_of", "set_bit", "union"]

EMPTY = np.uint64(0xFFFFFFFFFFFFFFFF)
_GOLDEN = np.uint64(0x9E3779B97F4A7C15)
#: Words of free bits in a row; the occupied bits follow.
WORDS = 8


def _morton_bits() -> NDArray[np.int64]:
    m = np.arange(512, dtype=np.int64)
    x = (m & 1) | (m >> 2 & 2) | (m >> 4 & 4)
    y = (m >> 1 & 1) | (m >> 3 & 2) | (m >> 5 & 4)
    z = (m >> 2 & 1) | (m >> 4 & 2) | (m >> 6 & 4)
    return x | y << 3 | z << 6


#: Block bit of each local Morton index (key & 511).
MORTON_BIT = _morton_bits()


@numba.njit(cache=True, inline="always")
def local_index(kx: int, ky: int, kz: int) -> int:
    """Bit of voxel key (kx, ky, kz) in its block: x + 8 y + 64 z of the keys' low 3 bits."""
    return int((kx & 7) | ((ky & 7) << 3) | ((kz & 7) << 6))


@numba.njit(cache=True, inline="always")
def find_slot(slots: NDArray[np.uint64], block: np.uint64) -> int:
    """Slot of ``block`` in an open-addressing table, or of the empty slot where it belongs."""
    mask = np.uint64(slots.size - 1)
    j = ((block * _GOLDEN) >> np.uint64(32)) & mask
    while slots[j] != block and slots[j] != EMPTY:
        j = (j + np.uint64(1)) & mask
    return int(j)


@numba.njit(cache=True)
def rehash(slots: NDArray[np.uint64], blocks: NDArray[np.uint64], n_blocks: int,
           size: int) -> tuple[NDArray[np.uint64], NDArray[np.int64]]:
    """Hash table of ``size`` slots (a power of two) holding the first ``n_blocks`` blocks."""
    new_slots = np.full(size, EMPTY, dtype=np.uint64)
    new_rows = np.zeros(size, dtype=np.int64)
    for r in range(n_blocks):
        j = find_slot(new_slots, blocks[r])
        new_slots[j] = blocks[r]
        new_rows[j] = r
    return new_slots, new_rows


@numba.njit(cache=True)
def new_table(capacity: int) -> Table:
    """An empty table with room for ``capacity`` blocks."""
    capacity = max(capacity, 16)
    size = 1 << int(np.ceil(np.log2(2 * capacity)))
    return (np.full(size, EMPTY, dtype=np.uint64), np.zeros(size, dtype=np.int64),
            np.zeros((capacity, 2 * WORDS), dtype=np.uint64), np.zeros(capacity, dtype=np.uint64))


@numba.njit(cache=True)
def reserve(table: Table, n_blocks: int, need: int) -> Table:
    """``table`` with room for ``need`` more blocks (rows doubled, hash kept half empty)."""
    slots, rows, bits, blocks = table
    if n_blocks + need > blocks.size:
        cap = max(2 * blocks.size, n_blocks + need)
        grown = np.zeros((cap, 2 * WORDS), dtype=np.uint64)
        grown_blocks = np.zeros(cap, dtype=np.uint64)
        for b in range(n_blocks):  # element by element: no shape check to compile
            for w in range(2 * WORDS):
                grown[b, w] = bits[b, w]
            grown_blocks[b] = blocks[b]
        bits, blocks = grown, grown_blocks
    if 2 * (n_blocks + need) > slots.size:
        size = slots.size
        while 2 * (n_blocks + need) > size:
            size *= 2
        slots, rows = rehash(slots, blocks, n_blocks, size)
    return slots, rows, bits, blocks


@numba.njit(cache=True, inline="always")
def row_of(table: Table, block: np.uint64, n_blocks: int) -> tuple[int, int]:
    """Row of ``block`` (added if new; room reserved by the caller); returns (row, n_blocks)."""
    slots, rows, _, blocks = table
    j = find_slot(slots, block)
    if slots[j] == EMPTY:
        slots[j] = block
        rows[j] = n_blocks
        blocks[n_blocks] = block
        n_blocks += 1
    return rows[j], n_blocks


@numba.njit(cache=True, inline="always")
def set_bit(bits: NDArray[np.uint64], row: int, word0: int, key: NDArray[np.int64]) -> None:
    """Set the bit of ``key`` (kx, ky, kz) in its block's row, in the words from ``word0``."""
    local = local_index(key[0], key[1], key[2])
    bits[row, word0 + (local >> 6)] |= np.uint64(1) << np.uint64(local & 63)


@numba.njit(cache=True)
def keys_to_blocks(keys: NDArray[np.uint64], word0: int,
                   ) -> tuple[NDArray[np.uint64], NDArray[np.uint64]]:
    """Blocks and bit rows of Morton ``keys``, set in the words from ``word0``."""
    n_blocks = int(np.int64(0))  # not a constant: a Literal[int](0) compiles a 2nd reserve
    table = reserve(new_table(keys.size // 64), n_blocks, keys.size)
    for key in keys:
        row, n_blocks = row_of(table, key >> np.uint64(9), n_blocks)
        local = MORTON_BIT[key & np.uint64(511)]
        table[2][row, word0 + (local >> 6)] |= np.uint64(1) << np.uint64(local & 63)
    return table[3][:n_blocks], table[2][:n_blocks]


@numba.njit(cache=True)
def union(blocks: NDArray[np.uint64], bits: NDArray[np.uint64], capacity: int) -> tuple[Table, int]:
    """Table of the rows ``bits`` (block codes ``blocks``, repeats OR-ed); (table, n_blocks)."""
    n_blocks = int(np.int64(0))  # as in keys_to_blocks
    table = reserve(new_table(capacity), n_blocks, blocks.size)
    for r in range(blocks.size):
        row, n_blocks = row_of(table, blocks[r], n_blocks)
        for w in range(2 * WORDS):
            table[2][row, w] |= bits[r, w]
    return table, n_blocks
