"""Numba kernels for the native Octomap: OctoMap keys, Morton codes and ray traversal.

Everything here reproduces the OctoMap library that ``pyoctomap`` 1.2 ships (its
``computeRayKeys`` keeps the ray length as float and casts the half-voxel step to
float; checked ray by ray against it) bit for bit: points and origins are float32
(``point3d``), keys are ``floor(coord / res) + 32768`` per axis for a tree of depth 16,
:func:`walk_hashed` and the lock-step walk of ``_lanes`` (started by :func:`flat_starts`)
step along each ray exactly like ``OcTreeBaseImpl::computeRayKeys`` (Amanatides & Woo,
with OctoMap's float/double mix), and :func:`prepare` truncates rays at the maximum
range like ``computeUpdate``. Keys are 48-bit Morton codes (x in the lowest bit of
each triple), so sorting them puts the eight children of every octree node next to
each other. ``_scan`` drives the walks over a scan and de-duplicates the keys.

The key can equal the end key only after exactly ``|dk|_1`` steps (each axis moves
monotonically), so :func:`walk_hashed` compares it then alone. The step limit
``|dk|_1`` + 5 only stops a ray that float round-off carries past its end voxel, so a walk
strays at most 4 voxels from the box of its origin and end keys.
"""

from __future__ import annotations

import numba
import numpy as np
from numpy.typing import NDArray

from alte.mappers.octree.blockset import Table, local_index, row_of

#: A ray (or rays): origin, origin key, end(s), end key(s) (float32 points, int64 keys).
Ray = tuple[NDArray[np.float32], NDArray[np.int64], NDArray[np.float32], NDArray[np.int64]]
#: A scan's rays as :func:`prepare` gives them: origin key, ends, their keys, hit flags.
Prepared = tuple[NDArray[np.int64], NDArray[np.float32], NDArray[np.int64], NDArray[np.bool_]]
#: Per-axis (step, tMax, tDelta) of a voxel walk.
Axis = tuple[int, float, float]

__all__ = ["TREE_DEPTH", "TREE_MAX_VAL", "Prepared", "Ray", "flat_starts", "morton",
           "morton_decode", "morton_encode", "prepare", "walk_hashed"]

TREE_DEPTH = 16
TREE_MAX_VAL = 32768
_KEY_LIMIT = 2 * TREE_MAX_VAL


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
def morton_encode(keys: NDArray[np.int64]) -> NDArray[np.uint64]:
    """(N, 3) integer keys in [0, 65536) -> (N,) uint64 Morton codes."""
    out = np.empty(keys.shape[0], dtype=np.uint64)
    for i in range(keys.shape[0]):
        out[i] = morton(keys[i, 0], keys[i, 1], keys[i, 2])
    return out


@numba.njit(cache=True)
def morton_decode(codes: NDArray[np.uint64]) -> NDArray[np.int64]:
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
def _ends(points: NDArray[np.float32], origin: NDArray[np.float32], max_range: float, factor: float,
          ) -> tuple[NDArray[np.float32], NDArray[np.int64], NDArray[np.bool_]]:
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
            ends[i, 0], ends[i, 1], ends[i, 2] = points[i, 0], points[i, 1], points[i, 2]
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
def _start(ray: Ray, res: float) -> tuple[Axis, Axis, Axis, float, int]:
    """Per-axis (step, tMax, tDelta), the float ray length and the steps to the end key."""
    origin, okey, end, ekey = ray
    dx, dy, dz = end[0] - origin[0], end[1] - origin[1], end[2] - origin[2]
    lf = np.float32(_norm(dx, dy, dz))  # float length = (float) direction.norm()
    last = abs(ekey[0] - okey[0]) + abs(ekey[1] - okey[1]) + abs(ekey[2] - okey[2])
    return (_axis(dx, lf, okey[0], origin[0], res), _axis(dy, lf, okey[1], origin[1], res),
            _axis(dz, lf, okey[2], origin[2], res), np.float64(lf), last)


@numba.njit(cache=True)
def flat_starts(rays: Ray, res: float, grid: NDArray[np.int64],
                ) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """Start data of the walkable rays in a flat bit grid (for :func:`_lanes.walk_lanes`):
    per ray tMax, tDelta, length and bit index, bit steps, end bit, step limit - 1.

    ``rays`` is (origin, origin key, ends, end keys); ``grid`` is the grid's first voxel
    key and its bit strides along y and z (x is 1). A ray is walked when its end key is
    valid and differs from the origin's.
    """
    origin, okey, ends, ekeys = rays
    n = ends.shape[0]
    floats, ints = np.empty((n, 7)), np.empty((n, 6), dtype=np.int64)
    strides = np.array([1, grid[3], grid[4]])
    first = 0
    for a in range(3):
        first += (okey[a] - grid[a]) * strides[a]
    m = 0
    for i in range(n):
        k = ekeys[i]
        if k[0] < 0 or (k[0] == okey[0] and k[1] == okey[1] and k[2] == okey[2]):
            continue
        (sx, tx, ddx), (sy, ty, ddy), (sz, tz, ddz), length, last = _start(
            (origin, okey, ends[i], k), res)
        floats[m, 0], floats[m, 1], floats[m, 2] = tx, ty, tz
        floats[m, 3], floats[m, 4], floats[m, 5], floats[m, 6] = ddx, ddy, ddz, length
        ints[m, 0], ints[m, 1], ints[m, 2], ints[m, 3] = first, sx, sy * grid[3], sz * grid[4]
        ints[m, 4] = first + (k[0] - okey[0]) + (k[1] - okey[1]) * grid[3] \
            + (k[2] - okey[2]) * grid[4]
        ints[m, 5] = last + 4  # the step limit ``|dk|_1`` + 5, less the origin's voxel
        m += 1
    return floats[:m], ints[:m]


@numba.njit(cache=True)
def walk_hashed(ray: Ray, res: float, limit: int, table: Table, n_blocks: int) -> int:
    """Set the bits of the free keys of ``computeRayKeys(origin, end)`` in a hashed block
    set (``_blockset``; room reserved by the caller); return the new block count;
    ``ray`` is (origin, origin key, end, end key).

    Entering a block costs a hash probe, so this serves scans too wide for a flat grid.
    """
    (sx, tx, ddx), (sy, ty, ddy), (sz, tz, ddz), length, last = _start(ray, res)
    okey, ekey = ray[1], ray[3]
    cx, cy, cz = okey[0], okey[1], okey[2]
    edge_x, edge_y, edge_z = (0 if sx > 0 else 7), (0 if sy > 0 else 7), (0 if sz > 0 else 7)
    row, n_blocks = row_of(table, morton(cx >> 3, cy >> 3, cz >> 3), n_blocks)
    bits = table[2]
    local = local_index(cx, cy, cz)
    bits[row, local >> 6] |= np.uint64(1) << np.uint64(local & 63)
    for s in range(1, limit):
        if tx < ty and tx < tz:
            cx += sx
            tx += ddx
            moved = (cx & 7) == edge_x
        elif ty < tz and not tx < ty:
            cy += sy
            ty += ddy
            moved = (cy & 7) == edge_y
        else:
            cz += sz
            tz += ddz
            moved = (cz & 7) == edge_z
        if s == last and cx == ekey[0] and cy == ekey[1] and cz == ekey[2]:
            break
        if min(tx, ty, tz) > length:
            break
        if moved:
            row, n_blocks = row_of(table, morton(cx >> 3, cy >> 3, cz >> 3), n_blocks)
        local = local_index(cx, cy, cz)
        bits[row, local >> 6] |= np.uint64(1) << np.uint64(local & 63)
    return n_blocks


@numba.njit(cache=True)
def prepare(points: NDArray[np.float32], origin: NDArray[np.float32], res: float,
            max_range: float) -> Prepared:
    """Origin key (-1 entries when off the key space), ray ends, their keys, hit flags."""
    factor = 1.0 / res
    okey = np.empty(3, dtype=np.int64)
    for i in range(3):
        okey[i] = _key(origin[i], factor)
    return (okey, *_ends(points, origin, max_range, factor))
