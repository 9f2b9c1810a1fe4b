"""Numba kernels for the native Octomap: OctoMap keys, Morton codes and ray traversal.

Everything here reproduces the OctoMap library that ``pyoctomap`` 1.2 ships (its
``computeRayKeys`` keeps the ray length as float and casts the half-voxel step to
float; checked ray by ray against it) bit for bit: points and origins are float32
(``point3d``), keys are ``floor(coord / res) + 32768`` per axis for a tree of depth 16,
and :func:`scan_keys` walks each ray exactly like ``OcTreeBaseImpl::computeRayKeys``
(Amanatides & Woo, with OctoMap's float/double mix) inside ``computeUpdate``
(max-range truncation, endpoint marked occupied only when within range).
Keys leave the kernels as 48-bit Morton codes (x in the lowest bit of each triple),
so sorting them puts the eight children of every octree node next to each other.

Per-scan de-duplication of ray voxels (OctoMap's ``KeySet``) is a set of 8x8x8 bit
blocks: an open-addressing hash table maps a block code (key >> 9) to a row of 512
bits. Consecutive voxels of a ray mostly share a block, so one probe serves several
voxels; memory follows the blocks a scan touches, not its bounding box.
"""

from __future__ import annotations

import numba
import numpy as np

__all__ = ["TREE_DEPTH", "TREE_MAX_VAL", "morton_decode", "morton_encode", "scan_keys"]

TREE_DEPTH = 16
TREE_MAX_VAL = 32768
_KEY_LIMIT = 2 * TREE_MAX_VAL

#: A ray's arrays: origin, origin key, end, end key, float and integer workspaces.
_Ray = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]
#: The block-bitmap key set: hash slots, slot rows, bit rows, row blocks.
_Table = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]


@numba.njit(cache=True, inline="always")
def _spread(v: np.uint64) -> np.uint64:
    """Insert two zero bits between the 16 low bits of ``v``."""
    v = v & np.uint64(0xFFFF)
    v = (v | (v << np.uint64(16))) & np.uint64(0x0000FF0000FF)
    v = (v | (v << np.uint64(8))) & np.uint64(0x00F00F00F00F)
    v = (v | (v << np.uint64(4))) & np.uint64(0x0C30C30C30C3)
    return (v | (v << np.uint64(2))) & np.uint64(0x249249249249)


@numba.njit(cache=True, inline="always")
def _compact(v: np.uint64) -> np.uint64:
    """Inverse of :func:`_spread`."""
    v = v & np.uint64(0x249249249249)
    v = (v | (v >> np.uint64(2))) & np.uint64(0x0C30C30C30C3)
    v = (v | (v >> np.uint64(4))) & np.uint64(0x00F00F00F00F)
    v = (v | (v >> np.uint64(8))) & np.uint64(0x0000FF0000FF)
    return (v | (v >> np.uint64(16))) & np.uint64(0xFFFF)


@numba.njit(cache=True, inline="always")
def _morton(kx: int, ky: int, kz: int) -> np.uint64:
    return (
        _spread(np.uint64(kx))
        | (_spread(np.uint64(ky)) << np.uint64(1))
        | (_spread(np.uint64(kz)) << np.uint64(2))
    )


@numba.njit(cache=True)
def morton_encode(keys: np.ndarray) -> np.ndarray:
    """(N, 3) integer keys in [0, 65536) -> (N,) uint64 Morton codes."""
    out = np.empty(keys.shape[0], dtype=np.uint64)
    for i in range(keys.shape[0]):
        out[i] = _morton(keys[i, 0], keys[i, 1], keys[i, 2])
    return out


@numba.njit(cache=True)
def morton_decode(codes: np.ndarray) -> np.ndarray:
    """(N,) uint64 Morton codes -> (N, 3) int64 keys."""
    out = np.empty((codes.shape[0], 3), dtype=np.int64)
    for i in range(codes.shape[0]):
        c = codes[i]
        out[i, 0] = _compact(c)
        out[i, 1] = _compact(c >> np.uint64(1))
        out[i, 2] = _compact(c >> np.uint64(2))
    return out


@numba.njit(cache=True, inline="always")
def _key(coord: np.float32, factor: float) -> int:
    """OctoMap ``coordToKey`` (double arithmetic on the float coordinate); -1 if out of range."""
    k = int(np.floor(factor * np.float64(coord))) + TREE_MAX_VAL
    if k < 0 or k >= _KEY_LIMIT:
        return -1
    return k


@numba.njit(cache=True, inline="always")
def _norm(dx: np.float32, dy: np.float32, dz: np.float32) -> float:
    """``Vector3::norm``: float squares and sum, double square root."""
    norm: float = np.sqrt(np.float64(dx * dx + dy * dy + dz * dz))
    return norm


@numba.njit(cache=True)
def _ends(points: np.ndarray, origin: np.ndarray, max_range: float, factor: float,
          ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Ray ends (truncated at ``max_range``), their keys and whether each end is a hit."""
    n = points.shape[0]
    ends = np.empty((n, 3), dtype=np.float32)
    keys = np.full((n, 3), -1, dtype=np.int64)
    hit = np.zeros(n, dtype=np.bool_)
    mr = np.float32(max_range)
    for i in range(n):
        dx = points[i, 0] - origin[0]
        dy = points[i, 1] - origin[1]
        dz = points[i, 2] - origin[2]
        length = _norm(dx, dy, dz)
        if max_range < 0.0 or length <= max_range:
            ends[i] = points[i]
            hit[i] = True
        else:  # origin + (p - origin).normalized() * (float) maxrange
            lf = np.float32(length)
            ends[i, 0] = origin[0] + (dx / lf) * mr
            ends[i, 1] = origin[1] + (dy / lf) * mr
            ends[i, 2] = origin[2] + (dz / lf) * mr
        kx = _key(ends[i, 0], factor)
        ky = _key(ends[i, 1], factor)
        kz = _key(ends[i, 2], factor)
        if kx >= 0 and ky >= 0 and kz >= 0:
            keys[i, 0] = kx
            keys[i, 1] = ky
            keys[i, 2] = kz
    return ends, keys, hit


_EMPTY = np.uint64(0xFFFFFFFFFFFFFFFF)
_GOLDEN = np.uint64(0x9E3779B97F4A7C15)
_LOW9 = np.uint64(511)


@numba.njit(cache=True)
def _find(slots: np.ndarray, block: np.uint64) -> int:
    """Slot of ``block`` in the table, or of the empty slot where it belongs."""
    mask = np.uint64(slots.size - 1)
    j = ((block * _GOLDEN) >> np.uint64(32)) & mask
    while slots[j] != block and slots[j] != _EMPTY:
        j = (j + np.uint64(1)) & mask
    return int(j)


@numba.njit(cache=True)
def _rehash(slots: np.ndarray, rows: np.ndarray, blocks: np.ndarray, n_blocks: int,
            ) -> tuple[np.ndarray, np.ndarray]:
    """Table twice as large holding the first ``n_blocks`` blocks."""
    new_slots = np.full(slots.size * 2, _EMPTY, dtype=np.uint64)
    new_rows = np.zeros(slots.size * 2, dtype=np.int64)
    for r in range(n_blocks):
        j = _find(new_slots, blocks[r])
        new_slots[j] = blocks[r]
        new_rows[j] = r
    return new_slots, new_rows


@numba.njit(cache=True)
def _grow_rows(bits: np.ndarray, blocks: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    new_bits = np.zeros((bits.shape[0] * 2, 8), dtype=np.uint64)
    new_bits[: bits.shape[0]] = bits
    new_blocks = np.zeros(blocks.size * 2, dtype=np.uint64)
    new_blocks[: blocks.size] = blocks
    return new_bits, new_blocks


@numba.njit(cache=True)
def _collect(bits: np.ndarray, blocks: np.ndarray, n_blocks: int, count: int) -> np.ndarray:
    """All keys of the set, sorted (blocks sorted, bits in Morton order within a block)."""
    out = np.empty(count, dtype=np.uint64)
    n = 0
    for r in np.argsort(blocks[:n_blocks]):
        base = blocks[r] << np.uint64(9)
        for w in range(8):
            word = bits[r, w]
            b = 0
            while word != np.uint64(0):
                if word & np.uint64(1):
                    out[n] = base | np.uint64(w * 64 + b)
                    n += 1
                word >>= np.uint64(1)
                b += 1
    return out


@numba.njit(cache=True)
def _row(slots: np.ndarray, rows: np.ndarray, blocks: np.ndarray, block: np.uint64,
         n_blocks: int) -> tuple[int, int]:
    """Row of ``block`` in the bit array, adding the block if new; returns (row, n_blocks)."""
    j = _find(slots, block)
    if slots[j] == _EMPTY:
        slots[j] = block
        rows[j] = n_blocks
        blocks[n_blocks] = block
        n_blocks += 1
    return rows[j], n_blocks


@numba.njit(cache=True)
def _setup(ray: _Ray, res: float) -> float:
    """Amanatides & Woo initialisation exactly as OctoMap; returns the ray length.

    Fills the per-scan workspaces: ``work`` = (tMax, tDelta), ``iwork`` = (key, step).
    """
    origin, okey, end, _, work, iwork = ray
    d = (end[0] - origin[0], end[1] - origin[1], end[2] - origin[2])
    lf = np.float32(_norm(d[0], d[1], d[2]))  # float length = (float) direction.norm()
    for i in range(3):
        iwork[0, i] = okey[i]
        iwork[1, i] = 0
        work[0, i] = np.finfo(np.float64).max
        work[1, i] = np.finfo(np.float64).max
        di = d[i] / lf
        if di != 0.0:
            iwork[1, i] = 1 if di > 0.0 else -1
            half = np.float64(np.float32(iwork[1, i] * res * 0.5))  # (float) cast as in OctoMap
            border = (np.float64(okey[i] - TREE_MAX_VAL) + 0.5) * res + half
            work[0, i] = (border - np.float64(origin[i])) / np.float64(di)
            work[1, i] = res / abs(np.float64(di))
    return np.float64(lf)


@numba.njit(cache=True)
def _walk(ray: _Ray, res: float, limit: int, table: _Table, n_blocks: int) -> tuple[int, int]:
    """Add the keys of ``computeRayKeys(origin, end)`` to the set; return (new keys, n_blocks).

    A ray visits at most |dk| + 1 voxels; ``limit`` (|dk| + 4) only stops a ray
    that float round-off carries past its end voxel (it then stops on the length test).
    """
    ekey, work, iwork = ray[3], ray[4], ray[5]
    slots, rows, bits, blocks = table
    length = _setup(ray, res)
    t_max, t_delta, cur, step = work[0], work[1], iwork[0], iwork[1]
    added, last, row = 0, _EMPTY, 0
    for it in range(limit):
        if it > 0:
            dim = (0 if t_max[0] < t_max[2] else 2) if t_max[0] < t_max[1] else (
                1 if t_max[1] < t_max[2] else 2)
            cur[dim] += step[dim]
            t_max[dim] += t_delta[dim]
            if cur[0] == ekey[0] and cur[1] == ekey[1] and cur[2] == ekey[2]:
                break
            if min(t_max[0], t_max[1], t_max[2]) > length:
                break
        key = _morton(cur[0], cur[1], cur[2])
        if key >> np.uint64(9) != last:
            last = key >> np.uint64(9)
            row, n_blocks = _row(slots, rows, blocks, last, n_blocks)
        low = key & _LOW9
        bit = np.uint64(1) << (low & np.uint64(63))
        old = bits[row, low >> np.uint64(6)]
        if not old & bit:
            bits[row, low >> np.uint64(6)] = old | bit
            added += 1
    return added, n_blocks


@numba.njit(cache=True)
def _reserve(table: _Table, n_blocks: int, need: int) -> _Table:
    """Grow ``table`` so ``need`` more blocks fit (rows and a half-empty hash table)."""
    slots, rows, bits, blocks = table
    while n_blocks + need > blocks.size:
        bits, blocks = _grow_rows(bits, blocks)
    while 2 * (n_blocks + need) > slots.size:
        slots, rows = _rehash(slots, rows, blocks, n_blocks)
    return slots, rows, bits, blocks


@numba.njit(cache=True)
def _free_keys(origin: np.ndarray, okey: np.ndarray, ends: np.ndarray, ekeys: np.ndarray,
               res: float) -> np.ndarray:
    """Sorted unique keys of every ray's free voxels (empty when the origin is off the tree)."""
    table = (
        np.full(1 << 12, _EMPTY, dtype=np.uint64),
        np.zeros(1 << 12, dtype=np.int64),
        np.zeros((1 << 11, 8), dtype=np.uint64),
        np.zeros(1 << 11, dtype=np.uint64),
    )
    work = np.empty((2, 3), dtype=np.float64)
    iwork = np.empty((2, 3), dtype=np.int64)
    n_blocks = 0
    count = 0
    if okey.min() < 0:
        return np.empty(0, dtype=np.uint64)
    for i in range(ends.shape[0]):
        k = ekeys[i]
        if k[0] < 0 or (k[0] == okey[0] and k[1] == okey[1] and k[2] == okey[2]):
            continue
        limit = abs(k[0] - okey[0]) + abs(k[1] - okey[1]) + abs(k[2] - okey[2]) + 5
        table = _reserve(table, n_blocks, limit + 1)
        ray = (origin, okey, ends[i], k, work, iwork)
        added, n_blocks = _walk(ray, res, limit, table, n_blocks)
        count += added
    return _collect(table[2], table[3], n_blocks, count)


@numba.njit(cache=True)
def scan_keys(points: np.ndarray, origin: np.ndarray, res: float, max_range: float,
              ) -> tuple[np.ndarray, np.ndarray]:
    """Sorted unique free and occupied Morton keys of one scan (OctoMap ``computeUpdate``).

    ``points`` (N, 3) and ``origin`` (3,) are float32. Free keys that are also
    occupied are NOT removed here (the caller does it on the sorted arrays). Rays
    whose origin or end lies outside the key range are skipped, as OctoMap does.
    Ray voxels are de-duplicated on the fly in a block-bitmap hash set, so the
    cost is one bit test per visited voxel and no sort of the repeats.
    """
    factor = 1.0 / res
    okey = np.empty(3, dtype=np.int64)
    for i in range(3):
        okey[i] = _key(origin[i], factor)
    ends, ekeys, hit = _ends(points, origin, max_range, factor)
    occ = np.empty(points.shape[0], dtype=np.uint64)
    n_occ = 0
    for i in range(points.shape[0]):
        if ekeys[i, 0] >= 0 and hit[i]:
            occ[n_occ] = _morton(ekeys[i, 0], ekeys[i, 1], ekeys[i, 2])
            n_occ += 1
    return _free_keys(origin, okey, ends, ekeys, res), np.unique(occ[:n_occ])
