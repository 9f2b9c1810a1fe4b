"""Numba kernels for the native Octomap: OctoMap keys, Morton codes and ray traversal.

Everything here reproduces the OctoMap library that ``pyoctomap`` 1.2 ships (its
``computeRayKeys`` keeps the ray length as float and casts the half-voxel step to
float; checked ray by ray against it) bit for bit: points and origins are float32
(``point3d``), keys are ``floor(coord / res) + 32768`` per axis for a tree of depth 16,
:func:`walk_dense` / :func:`walk_hashed` step along each ray exactly like
``OcTreeBaseImpl::computeRayKeys`` (Amanatides & Woo, with OctoMap's float/double
mix), and :func:`prepare` truncates rays at the maximum range like ``computeUpdate``.
Keys are 48-bit Morton codes (x in the lowest bit of each triple), so sorting them
puts the eight children of every octree node next to each other. ``_scan`` drives
the walks over a scan and de-duplicates the keys.

A walk keeps its voxel in scalars: its key and its local Morton index in the 8x8x8
block, kept per axis in dilated form (x on bits 0, 3, 6; y and z shifted by 1 and 2)
and moved by one add that also tells when the walk leaves the block. The key can
equal the end key only after exactly |dk|_1 steps (each axis moves monotonically),
so it is compared then alone. The step limit |dk|_1 + 5 only stops a ray that float
round-off carries past its end voxel, so a walk strays at most 4 voxels from the box
of its origin and end keys.
"""

from __future__ import annotations

import numba
import numpy as np

from alte.mappers._blockset import LOCAL, Table, row_of

#: A ray (or rays): origin, origin key, end(s), end key(s).
Ray = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]
#: Per-axis (step, tMax, tDelta) of a voxel walk.
Axis = tuple[int, float, float]

__all__ = ["TREE_DEPTH", "TREE_MAX_VAL", "morton", "morton_decode", "morton_encode", "prepare",
           "walk_dense", "walk_hashed"]

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
def morton(kx: int, ky: int, kz: int) -> np.uint64:
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
        out[i] = morton(keys[i, 0], keys[i, 1], keys[i, 2])
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


@numba.njit(cache=True, inline="always")
def _axis(delta: np.float32, lf: np.float32, okey: int, origin: np.float32,
          res: float) -> tuple[int, float, float]:
    """Amanatides & Woo set-up of one axis exactly as OctoMap: (step, tMax, tDelta)."""
    di = delta / lf  # float direction component
    if di == 0.0:
        return 0, np.finfo(np.float64).max, np.finfo(np.float64).max
    step = 1 if di > 0.0 else -1
    half = np.float64(np.float32(step * res * 0.5))  # (float) cast as in OctoMap
    border = (np.float64(okey - TREE_MAX_VAL) + 0.5) * res + half
    return step, (border - np.float64(origin)) / np.float64(di), res / abs(np.float64(di))


@numba.njit(cache=True, inline="always")
def _dilated(step: int, mask: int) -> tuple[int, int]:
    """(fill, wrap) of one axis' dilated local index: ``((l | fill) + step) & mask`` moves
    it one voxel, and it equals ``wrap`` exactly when the walk left the block."""
    if step > 0:
        return 511 & ~mask, 0
    return 0, mask


@numba.njit(cache=True, inline="always")
def _start(ray: Ray, res: float) -> tuple[Axis, Axis, Axis, float, int]:
    """Per-axis (step, tMax, tDelta), the float ray length and the steps to the end key."""
    origin, okey, end, ekey = ray
    dx, dy, dz = end[0] - origin[0], end[1] - origin[1], end[2] - origin[2]
    lf = np.float32(_norm(dx, dy, dz))  # float length = (float) direction.norm()
    last = abs(ekey[0] - okey[0]) + abs(ekey[1] - okey[1]) + abs(ekey[2] - okey[2])
    return (_axis(dx, lf, okey[0], origin[0], res), _axis(dy, lf, okey[1], origin[1], res),
            _axis(dz, lf, okey[2], origin[2], res), np.float64(lf), last)


@numba.njit(cache=True)
def walk_dense(ray: Ray, res: float, limit: int, grid: np.ndarray, box: np.ndarray) -> None:
    """Set the bits of the free keys of ``computeRayKeys(origin, end)`` in a dense array;
    ``ray`` is (origin, origin key, end, end key).

    ``grid`` has 8 uint64 words per 8x8x8 block of the block box ``box`` (x0, y0, z0,
    nbx, nby, nbz; x fastest), so entering a block adds a fixed jump to the word offset.
    """
    (sx, tx, ddx), (sy, ty, ddy), (sz, tz, ddz), length, last = _start(ray, res)
    okey, ekey = ray[1], ray[3]
    cx, cy, cz = okey[0], okey[1], okey[2]
    lx, ly, lz = LOCAL[cx & 7], LOCAL[cy & 7] << 1, LOCAL[cz & 7] << 2
    fx, wx = _dilated(sx, 73)
    fy, wy = _dilated(sy, 146)
    fz, wz = _dilated(sz, 292)
    nbx, nbxy = box[3], box[3] * box[4]
    base = 8 * ((cx >> 3) - box[0] + nbx * ((cy >> 3) - box[1]) + nbxy * ((cz >> 3) - box[2]))
    jx, jy, jz = 8 * sx, 8 * sy * nbx, 8 * sz * nbxy
    local = lx | ly | lz
    grid[base + (local >> 6)] |= np.uint64(1) << np.uint64(local & 63)
    for s in range(1, limit):
        if tx < ty and tx < tz:
            cx += sx
            tx += ddx
            lx = ((lx | fx) + sx) & 73
            if lx == wx:
                base += jx
        elif ty < tz and not tx < ty:
            cy += sy
            ty += ddy
            ly = ((ly | fy) + (sy << 1)) & 146
            if ly == wy:
                base += jy
        else:
            cz += sz
            tz += ddz
            lz = ((lz | fz) + (sz << 2)) & 292
            if lz == wz:
                base += jz
        if s == last and cx == ekey[0] and cy == ekey[1] and cz == ekey[2]:
            break
        if min(tx, ty, tz) > length:
            break
        local = lx | ly | lz
        grid[base + (local >> 6)] |= np.uint64(1) << np.uint64(local & 63)


@numba.njit(cache=True)
def walk_hashed(ray: Ray, res: float, limit: int, table: Table, n_blocks: int) -> int:
    """Set the bits of the free keys of ``computeRayKeys(origin, end)`` in a hashed block
    set (``_blockset``; room reserved by the caller); return the new block count;
    ``ray`` is (origin, origin key, end, end key).

    Entering a block costs a hash probe, so this serves scans too wide for a dense array.
    """
    (sx, tx, ddx), (sy, ty, ddy), (sz, tz, ddz), length, last = _start(ray, res)
    okey, ekey = ray[1], ray[3]
    cx, cy, cz = okey[0], okey[1], okey[2]
    lx, ly, lz = LOCAL[cx & 7], LOCAL[cy & 7] << 1, LOCAL[cz & 7] << 2
    fx, wx = _dilated(sx, 73)
    fy, wy = _dilated(sy, 146)
    fz, wz = _dilated(sz, 292)
    row, n_blocks = row_of(table, morton(cx >> 3, cy >> 3, cz >> 3), n_blocks)
    grid = table[2].reshape(-1)
    base = 16 * row
    local = lx | ly | lz
    grid[base + (local >> 6)] |= np.uint64(1) << np.uint64(local & 63)
    for s in range(1, limit):
        moved = False
        if tx < ty and tx < tz:
            cx += sx
            tx += ddx
            lx = ((lx | fx) + sx) & 73
            moved = lx == wx
        elif ty < tz and not tx < ty:
            cy += sy
            ty += ddy
            ly = ((ly | fy) + (sy << 1)) & 146
            moved = ly == wy
        else:
            cz += sz
            tz += ddz
            lz = ((lz | fz) + (sz << 2)) & 292
            moved = lz == wz
        if s == last and cx == ekey[0] and cy == ekey[1] and cz == ekey[2]:
            break
        if min(tx, ty, tz) > length:
            break
        if moved:
            row, n_blocks = row_of(table, morton(cx >> 3, cy >> 3, cz >> 3), n_blocks)
            base = 16 * row
        local = lx | ly | lz
        grid[base + (local >> 6)] |= np.uint64(1) << np.uint64(local & 63)
    return n_blocks


@numba.njit(cache=True)
def prepare(points: np.ndarray, origin: np.ndarray, res: float,
            max_range: float) -> Ray:
    """Origin key (-1 entries when off the key space), ray ends, their keys, hit flags."""
    factor = 1.0 / res
    okey = np.empty(3, dtype=np.int64)
    for i in range(3):
        okey[i] = _key(origin[i], factor)
    return (okey, *_ends(points, origin, max_range, factor))
