"""One scan of the native Octomap: OctoMap's ``computeUpdate`` as blocks of key bits.

Every ray of the scan is walked into a set of voxel bits, which de-duplicates the keys
as OctoMap's ``KeySet`` does. When the scan's block box (origin and ray ends, padded by
one block) is small, as for a LiDAR scan (0.4-3 MiB of bits for sim_nav_1 at 0.2 m),
the bits live in a flat grid over that box, x rows of 64-bit words, and the rays are
walked four at a time by ``_lanes.walk_lanes``; the set bits are then gathered into
8x8x8 blocks. A larger box falls back to a hash table of blocks walked ray by ray
(``_raycast.walk_hashed``, ``_blockset``). The scan leaves as the touched blocks with
8 words of free and 8 of occupied bits each, which the map applies block by block
(``_voxelstore.VoxelStore``) with no sort.

The grid and the box's block-to-row table are reused from scan to scan
(:class:`ScanWork`): a scan leaves them cleared, so none is allocated or zeroed per scan.
"""

from __future__ import annotations

import numba
import numpy as np
from numba.cpython.unsafe.numbers import trailing_zeros
from numpy.typing import NDArray

from alte.mappers.octomap.cost import scan_cost, skip_ray, walk_limit, walk_steps
from alte.mappers.octomap.lanes import walk_lanes
from alte.mappers.octree.blockset import (
    WORDS,
    local_index,
    new_table,
    reserve,
    row_of,
    set_bit,
    union,
)
from alte.mappers.octree.raycast import Ray, flat_starts, morton, prepare, walk_hashed

__all__ = ["DENSE_ANY_WORDS", "DENSE_MAX_WORDS", "WORDS_PER_STEP", "ScanWork", "scan_blocks",
           "scan_cost"]

#: Largest flat bit grid (uint64 words; 2^24 = 128 MiB, of which only the pages the rays
#: cross are ever written) before the hashed set is used.
DENSE_MAX_WORDS = 1 << 24
#: A flat grid above 2^21 words (16 MiB) is used only with at most WORDS_PER_STEP words per
#: ray step: the passes over the grid after the walk cost a step's hashing per few words
#: (sim_nav_1's full-range scans at 0.1 m: flat twice as fast as hashed).
DENSE_ANY_WORDS = 1 << 21
WORDS_PER_STEP = 8
#: What the kernels pass: a scan's block codes and bit rows (8 free, then 8 occupied words);
#: :class:`ScanWork`'s bit grid, cell rows and flags; both (the work grown where needed).
_Blocks = tuple[NDArray[np.uint64], NDArray[np.uint64]]
_Work = tuple[NDArray[np.uint64], NDArray[np.int64], NDArray[np.uint64]]
_Scanned = tuple[NDArray[np.uint64], NDArray[np.uint64], *_Work]


class ScanWork:
    """Buffers reused by the scans of one map: the flat bit grid and cell flags (zero
    between scans), the box cell -> row table (-1), the last scan's block count (the
    hashed set's first size) and ``steps``, its scans' ray steps (:func:`scan_cost`)."""

    def __init__(self) -> None:
        self.grid = np.zeros(1, dtype=np.uint64)
        self.cell = np.full(8, -1, dtype=np.int64)
        self.flags = np.zeros(1, dtype=np.uint64)
        self.blocks = 1024
        self.steps = 0


@numba.njit(cache=True)
def _box(okey: NDArray[np.int64], ekeys: NDArray[np.int64]) -> NDArray[np.int64]:
    """Block box of the origin and the valid ray ends, padded by one block: (x0, y0, z0,
    nbx, nby, nbz), nbx rounded up to whole grid words (8 blocks). A walk strays at most
    4 voxels from its own box, so it stays inside."""
    lo, hi = okey >> 3, okey >> 3
    for i in range(ekeys.shape[0]):
        if ekeys[i, 0] >= 0:
            for a in range(3):
                lo[a] = min(lo[a], ekeys[i, a] >> 3)
                hi[a] = max(hi[a], ekeys[i, a] >> 3)
    size = hi - lo + 3
    size[0] = (size[0] + 7) // 8 * 8
    return np.concatenate((lo - 1, size))


@numba.njit(cache=True, inline="always")
def _cell(box: NDArray[np.int64], k: NDArray[np.int64]) -> int:
    """Box cell (block index, x fastest) of voxel key ``k``."""
    return int((((k[2] >> 3) - box[2]) * box[4] + (k[1] >> 3) - box[1]) * box[3]
               + (k[0] >> 3) - box[0])


@numba.njit(cache=True)
def _mark(grid: NDArray[np.uint64], box: NDArray[np.int64], flags: NDArray[np.uint64],
          ekeys: NDArray[np.int64], hit: NDArray[np.bool_]) -> None:
    """Flag the box cells holding set bits or occupied ends: bit 8j of ``flags[c >> 3]``
    for cell ``c`` with ``c & 7 == j`` (a grid word spans the x rows of 8 cells)."""
    nwx, nby = box[3] // 8, box[4]
    low = np.uint64(0x0101010101010101)
    for f in range(nwx * nby * box[5]):
        rest, xw = divmod(f, nwx)
        bz, by = divmod(rest, nby)
        w = np.uint64(0)
        for zz in range(8):
            first = ((8 * bz + zz) * 8 * nby + 8 * by) * nwx + xw
            for yy in range(8):
                w |= grid[first + yy * nwx]
        w |= w >> np.uint64(4)
        w |= w >> np.uint64(2)
        flags[f] = (w | (w >> np.uint64(1))) & low
    for r in range(ekeys.shape[0]):
        if ekeys[r, 0] >= 0 and hit[r]:
            c = _cell(box, ekeys[r])
            flags[c >> 3] |= np.uint64(1) << np.uint64(8 * (c & 7))


@numba.njit(cache=True)
def _rows(box: NDArray[np.int64], flags: NDArray[np.uint64], cell: NDArray[np.int64],
          ) -> tuple[NDArray[np.uint64], NDArray[np.int64]]:
    """A row per flagged cell (``cell[c]`` = its row): block codes and each row's cell."""
    nwx, nby = box[3] // 8, box[4]
    count = 0
    for f in range(nwx * nby * box[5]):
        t = flags[f]
        while t:
            t &= t - np.uint64(1)
            count += 1
    blocks, where = np.empty(count, dtype=np.uint64), np.empty(count, dtype=np.int64)
    n = 0
    for f in range(nwx * nby * box[5]):
        t = flags[f]
        while t:
            j = int(trailing_zeros(t)) >> 3  # type: ignore[call-arg]  # numba intrinsic
            t &= t - np.uint64(1)
            rest, xw = divmod(f, nwx)
            bz, by = divmod(rest, nby)
            cell[8 * f + j] = n
            blocks[n], where[n] = morton(box[0] + 8 * xw + j, box[1] + by, box[2] + bz), 8 * f + j
            n += 1
    return blocks, where


@numba.njit(cache=True, inline="always")
def _swap(rows: NDArray[np.uint64], a: int, b: int, shift: int, mask: np.uint64) -> None:
    """Swap the ``mask`` lanes of ``rows[b]`` with the lanes ``shift`` bits up in ``rows[a]``."""
    t = ((rows[a] >> np.uint64(shift)) ^ rows[b]) & mask
    rows[a] ^= t << np.uint64(shift)
    rows[b] ^= t


@numba.njit(cache=True, inline="always")
def _transpose(rows: NDArray[np.uint64]) -> None:
    """Transpose 8 words as an 8x8 byte matrix: byte j of word i <-> byte i of word j."""
    for i in range(4):
        _swap(rows, i, i + 4, 32, np.uint64(0x00000000FFFFFFFF))
    for i in (0, 1, 4, 5):
        _swap(rows, i, i + 2, 16, np.uint64(0x0000FFFF0000FFFF))
    for i in (0, 2, 4, 6):
        _swap(rows, i, i + 1, 8, np.uint64(0x00FF00FF00FF00FF))


@numba.njit(cache=True)
def _gather(grid: NDArray[np.uint64], box: NDArray[np.int64], cell: NDArray[np.int64],
            flags: NDArray[np.uint64], bits: NDArray[np.uint64]) -> None:
    """Copy the grid's x rows (bytes) into the free words of their cells' rows (row
    ``bits.shape[0] - 1`` takes the unflagged cells' zeros), flagged groups of 8 cells at
    a time: the 8 y rows of a z slice are 8 words whose byte transpose gives each cell's
    word of that slice. Clears the grid and the flags."""
    nwx, nby, spare = box[3] // 8, box[4], bits.shape[0] - 1
    rows, words = np.empty(8, dtype=np.int64), np.empty(8, dtype=np.uint64)
    for f in range(nwx * nby * box[5]):
        if flags[f] == 0:
            continue
        flags[f] = 0
        rest, xw = divmod(f, nwx)
        bz, by = divmod(rest, nby)
        for j in range(8):
            rows[j] = spare if cell[8 * f + j] < 0 else cell[8 * f + j]
        for zz in range(8):
            first = ((8 * bz + zz) * 8 * nby + 8 * by) * nwx + xw
            for yy in range(8):
                words[yy] = grid[first + yy * nwx]
                grid[first + yy * nwx] = 0
            _transpose(words)
            for j in range(8):
                bits[rows[j], zz] = words[j]


@numba.njit(cache=True)
def _hits(bits: NDArray[np.uint64], box: NDArray[np.int64], cell: NDArray[np.int64],
          ekeys: NDArray[np.int64], hit: NDArray[np.bool_]) -> None:
    """Set the occupied end voxels in their rows' occupied words (occupied beats free)."""
    for i in range(ekeys.shape[0]):
        k = ekeys[i]
        if k[0] >= 0 and hit[i]:
            local = local_index(k[0], k[1], k[2])
            bit = np.uint64(1) << np.uint64(local & 63)
            r = cell[_cell(box, k)]
            bits[r, local >> 6] &= ~bit
            bits[r, WORDS + (local >> 6)] |= bit


@numba.njit(cache=True)
def _dense(rays: Ray, res: float, box: NDArray[np.int64], work: _Work,
           hit: NDArray[np.bool_]) -> _Scanned:
    """Blocks and bit rows of ``rays`` walked in the flat grid over ``box``, and the work
    buffers (grown when the box needs more)."""
    grid, cell, flags = work
    cells = box[3] * box[4] * box[5]
    if grid.size <= 8 * cells:  # a quarter more than this box needs: boxes vary a little
        grid = np.zeros(10 * cells + 1, dtype=np.uint64)
    if cell.size < cells:
        cell = np.full(cells + cells // 4 // 8 * 8, -1, dtype=np.int64)
        flags = np.zeros(cell.size // 8, dtype=np.uint64)
    corner = 8 * box[:3]
    strides = np.array([corner[0], corner[1], corner[2], 8 * box[3], 64 * box[3] * box[4]])
    floats, ints = flat_starts(rays, res, strides)
    walk_lanes(floats, ints, grid, 64 * 8 * cells)
    grid[8 * cells] = 0  # the spare word of stopped and parked lanes
    _mark(grid, box, flags, rays[3], hit)
    blocks, where = _rows(box, flags, cell)
    bits = np.zeros((blocks.size + 1, 2 * WORDS), dtype=np.uint64)
    _gather(grid, box, cell, flags, bits)
    _hits(bits, box, cell, rays[3], hit)
    cell[where] = -1
    return blocks, bits[:-1], grid, cell, flags


@numba.njit(cache=True)
def _rays_hashed(rays: Ray, res: float, capacity: int) -> _Blocks:
    """Blocks and bit rows of ``rays`` (origin, its key, ends, their keys), walked into a
    hash table."""
    origin, okey, ends, ekeys = rays
    table, n_blocks = new_table(capacity), int(np.int64(0))  # no Literal: blockset.keys_to_blocks
    for i in range(ends.shape[0]):
        k = ekeys[i]
        if skip_ray(okey, k):
            continue
        blocks = (abs((k[0] >> 3) - (okey[0] >> 3)) + abs((k[1] >> 3) - (okey[1] >> 3))
                  + abs((k[2] >> 3) - (okey[2] >> 3)) + 6)  # 4 voxels cross <= 1 block more
        limit = walk_limit(okey, k)
        table = reserve(table, n_blocks, min(limit, blocks))
        n_blocks = walk_hashed((origin, okey, ends[i], k), res, limit, table, n_blocks)
    return table[3][:n_blocks], table[2][:n_blocks]


@numba.njit(cache=True)
def _finish(blocks: NDArray[np.uint64], bits: NDArray[np.uint64], ekeys: NDArray[np.int64],
            hit: NDArray[np.bool_]) -> _Blocks:
    """Union of the rays' blocks plus the occupied end voxels; free bits lose occupied ones."""
    table, n_blocks = union(blocks, bits, blocks.size + 64)
    table = reserve(table, n_blocks, ekeys.shape[0])
    for i in range(ekeys.shape[0]):
        k = ekeys[i]
        if k[0] >= 0 and hit[i]:
            row, n_blocks = row_of(table, morton(k[0] >> 3, k[1] >> 3, k[2] >> 3), n_blocks)
            set_bit(table[2], row, WORDS, k)
    out = table[2][:n_blocks]
    for r in range(n_blocks):
        for w in range(WORDS):
            out[r, w] &= ~out[r, WORDS + w]
    return table[3][:n_blocks], out


@numba.njit(cache=True)
def _scan(cloud: tuple[NDArray[np.float32], NDArray[np.float32]], res: float, max_range: float,
          work: _Work, sizes: tuple[int, int, int, int]
          ) -> tuple[_Scanned, int]:
    """:func:`scan_blocks` of ``cloud`` (points, origin) in one compiled call; ``sizes``
    is the hashed set's first capacity and the flat grid's limits (DENSE_MAX_WORDS,
    DENSE_ANY_WORDS, WORDS_PER_STEP). Also returns the work buffers, and the ray steps."""
    (points, origin), (capacity, most, anyway, per_step) = cloud, sizes
    okey, ends, ekeys, hit = prepare(points, origin, res, max_range)
    steps, cost = walk_steps(okey, ekeys)
    box = _box(okey, ekeys)
    words = 8 * box[3] * box[4] * box[5]
    if okey.min() >= 0 and words <= most and (words <= anyway or words <= per_step * steps):
        return _dense((origin, okey, ends, ekeys), res, box, work, hit), cost
    blocks, bits = np.empty(0, np.uint64), np.empty((0, 2 * WORDS), np.uint64)
    if okey.min() >= 0:
        blocks, bits = _rays_hashed((origin, okey, ends, ekeys), res, capacity)
    blocks, bits = _finish(blocks, bits, ekeys, hit)
    return (blocks, bits, work[0], work[1], work[2]), cost


def scan_blocks(points: NDArray[np.float32], origin: NDArray[np.float32], res: float,
                max_range: float, work: ScanWork | None = None) -> _Blocks:
    """One scan's update as (block codes, rows of 8 free + 8 occupied words).

    Free bits: every voxel a ray crosses before its end voxel; occupied bits: end
    voxels of rays within ``max_range``; occupied beats free, so they are disjoint.
    ``points`` (N, 3) and ``origin`` (3,) are float32; rays whose origin or end lies
    outside the key space are skipped, as OctoMap does. ``work`` keeps the buffers of
    a map's scans (fresh ones without).
    """
    work = work or ScanWork()
    (blocks, bits, work.grid, work.cell, work.flags), steps = _scan(
        (points, origin), res, max_range, (work.grid, work.cell, work.flags),
        (work.blocks + 64, DENSE_MAX_WORDS, DENSE_ANY_WORDS, WORDS_PER_STEP))
    work.blocks = blocks.size + blocks.size // 4
    work.steps += steps
    return blocks, bits
