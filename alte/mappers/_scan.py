"""One scan of the native Octomap: OctoMap's ``computeUpdate`` as blocks of key bits.

Every ray of the scan is walked (``_raycast.walk_dense`` or ``walk_hashed``) into a set of
8x8x8 bit blocks, which de-duplicates the keys as OctoMap's ``KeySet`` does. When
the scan's block box (origin and ray ends, padded by one block) is small, as for a
LiDAR scan (0.4-1.2 MiB of bits for sim_nav_1 at 0.2 m), the bits live in a dense
array over that box: entering a block is an add, with no hashing; a larger box
falls back to a hash table of blocks (``_blockset``). The scan leaves as the touched
blocks with 8 words of free and 8 of occupied bits each, which the map applies
block by block (``_octree.VoxelStore``) with no sort.

Rays are independent, so with ``threads`` > 1 they are walked in chunks by a thread
pool (the kernels release the GIL), each chunk into its own set; the union of the
sets does not depend on the split.
"""

from __future__ import annotations

import itertools
from concurrent.futures import ThreadPoolExecutor

import numba
import numpy as np

from alte.mappers._blockset import WORDS, new_table, reserve, row_of, set_bit, union
from alte.mappers._raycast import Ray, morton, prepare, walk_dense, walk_hashed

__all__ = ["DENSE_MAX_WORDS", "scan_blocks"]

#: Largest dense bit box (uint64 words; 2^21 = 16 MiB) before the hashed set is used.
DENSE_MAX_WORDS = 1 << 21
#: Rays per chunk below which a scan is walked in the calling thread.
_MIN_CHUNK = 256
_POOLS: dict[int, ThreadPoolExecutor] = {}


@numba.njit(cache=True, inline="always")
def _skip(okey: np.ndarray, k: np.ndarray) -> bool:
    """A ray is walked when its end key is valid and differs from the origin's."""
    return bool(k[0] < 0 or (k[0] == okey[0] and k[1] == okey[1] and k[2] == okey[2]))


@numba.njit(cache=True, inline="always")
def _limit(okey: np.ndarray, k: np.ndarray) -> int:
    return int(abs(k[0] - okey[0]) + abs(k[1] - okey[1]) + abs(k[2] - okey[2]) + 5)


@numba.njit(cache=True)
def _box(okey: np.ndarray, ekeys: np.ndarray) -> np.ndarray:
    """Block box of the origin and the valid ray ends, padded by one block: (x0, y0, z0,
    nbx, nby, nbz). A walk strays at most 4 voxels from its own box, so it stays inside."""
    lo, hi = okey >> 3, okey >> 3
    for i in range(ekeys.shape[0]):
        if ekeys[i, 0] >= 0:
            for a in range(3):
                lo[a] = min(lo[a], ekeys[i, a] >> 3)
                hi[a] = max(hi[a], ekeys[i, a] >> 3)
    return np.concatenate((lo - 1, hi - lo + 3))


@numba.njit(cache=True, nogil=True)
def _rays_dense(rays: Ray, res: float, box: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Blocks and bit rows of ``rays`` (origin, its key, ends, their keys), walked into a
    dense bit array over ``box``."""
    origin, okey, ends, ekeys = rays
    nbx, nby, nbz = box[3], box[4], box[5]
    grid = np.zeros(WORDS * nbx * nby * nbz, dtype=np.uint64)
    for i in range(ends.shape[0]):
        if not _skip(okey, ekeys[i]):
            ray = (origin, okey, ends[i], ekeys[i])
            walk_dense(ray, res, _limit(okey, ekeys[i]), grid, box)
    used = np.empty(nbx * nby * nbz, dtype=np.int64)
    n_used = 0
    for b in range(used.size):
        for w in range(WORDS):
            if grid[WORDS * b + w]:
                used[n_used] = b
                n_used += 1
                break
    blocks = np.empty(n_used, dtype=np.uint64)
    bits = np.zeros((n_used, 2 * WORDS), dtype=np.uint64)
    for r in range(n_used):
        iz, rest = divmod(used[r], nbx * nby)
        iy, ix = divmod(rest, nbx)
        blocks[r] = morton(box[0] + ix, box[1] + iy, box[2] + iz)
        bits[r, :WORDS] = grid[WORDS * used[r]:WORDS * used[r] + WORDS]
    return blocks, bits


@numba.njit(cache=True, nogil=True)
def _rays_hashed(rays: Ray, res: float, capacity: int) -> tuple[np.ndarray, np.ndarray]:
    """Blocks and bit rows of ``rays`` (as :func:`_rays_dense`), walked into a hash table."""
    origin, okey, ends, ekeys = rays
    table, n_blocks = new_table(capacity), 0
    for i in range(ends.shape[0]):
        k = ekeys[i]
        if _skip(okey, k):
            continue
        blocks = (abs((k[0] >> 3) - (okey[0] >> 3)) + abs((k[1] >> 3) - (okey[1] >> 3))
                  + abs((k[2] >> 3) - (okey[2] >> 3)) + 6)  # 4 voxels cross <= 1 block more
        table = reserve(table, n_blocks, min(_limit(okey, k), blocks))
        n_blocks = walk_hashed((origin, okey, ends[i], k), res, _limit(okey, k), table, n_blocks)
    return table[3][:n_blocks], table[2][:n_blocks]


@numba.njit(cache=True)
def _finish(blocks: np.ndarray, bits: np.ndarray, ekeys: np.ndarray,
            hit: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
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


def _pool(workers: int) -> ThreadPoolExecutor:
    if workers not in _POOLS:
        _POOLS[workers] = ThreadPoolExecutor(workers, thread_name_prefix="alte-raycast")
    return _POOLS[workers]


def scan_blocks(points: np.ndarray, origin: np.ndarray, res: float, max_range: float, *,
                capacity: int = 1024, threads: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """One scan's update as (block codes, rows of 8 free + 8 occupied words).

    Free bits: every voxel a ray crosses before its end voxel; occupied bits: end
    voxels of rays within ``max_range``; occupied beats free, so they are disjoint.
    ``points`` (N, 3) and ``origin`` (3,) are float32; rays whose origin or end lies
    outside the key space are skipped, as OctoMap does. ``capacity`` guesses the block
    count of a hashed set; ``threads`` > 1 walks 2 x ``threads`` chunks in a pool.
    """
    okey, ends, ekeys, hit = prepare(points, origin, res, max_range)
    if okey.min() < 0:
        return _finish(np.empty(0, np.uint64), np.empty((0, 2 * WORDS), np.uint64), ekeys, hit)
    box = _box(okey, ekeys)
    dense = WORDS * box[3] * box[4] * box[5] <= DENSE_MAX_WORDS

    def rays(a: int, b: int) -> tuple[np.ndarray, np.ndarray]:
        if dense:
            return _rays_dense((origin, okey, ends[a:b], ekeys[a:b]), res, box)
        return _rays_hashed((origin, okey, ends[a:b], ekeys[a:b]), res, capacity)

    chunks = min(2 * threads, len(ends) // _MIN_CHUNK) if threads > 1 else 1
    if chunks <= 1:
        return _finish(*rays(0, len(ends)), ekeys, hit)
    cuts = [len(ends) * i // chunks for i in range(chunks + 1)]
    jobs = [_pool(threads).submit(rays, a, b) for a, b in itertools.pairwise(cuts)]
    parts = [job.result() for job in jobs]
    return _finish(np.concatenate([p[0] for p in parts]), np.concatenate([p[1] for p in parts]),
                   ekeys, hit)
