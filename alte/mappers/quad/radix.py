"""Points sorted by their finest cell key, for the tree walk (:mod:`~alte.mappers.quad.treebuild`).

The points are sorted by *packed* keys, ``key << shift | index``: one int64 array moved
per radix pass, and the index makes the order stable. A whole cloud's keys are sorted
by their top 6 bits first and the 64 runs then side by side on every thread.
"""

from __future__ import annotations

import numba
import numpy as np
from numpy.typing import NDArray

from alte._numba import CLOUD_MIN, threads_for
from alte.mappers.quad.cellstats import sort_keys

__all__ = ["Sorted", "sort_points"]

#: Below this many points numba's quicksort of the packed keys beats the radix passes.
_RADIX_MIN = 1 << 14
#: Points sorted by :func:`sort_points`: ``(packed, shift, values)``; ``shift`` 0 when
#: the keys alone are sorted and ``values`` are in their order.
Sorted = tuple[NDArray[np.int64], int, NDArray[np.float64]]

@numba.njit(cache=True, parallel=True)
def _pack(keys: NDArray[np.int64], shift: int, out: NDArray[np.int64],
          scratch: NDArray[np.int64]) -> None:
    """``out[i] = keys[i] << shift | i`` (``out`` may be ``keys``) and ``scratch`` touched,
    on every thread: a fresh array costs a page fault per 4 KiB at its first touch."""
    for i in numba.prange(keys.size):
        out[i] = (keys[i] << shift) | i
        scratch[i] = 0


@numba.njit(cache=True)
def _radix(buffers: tuple[NDArray[np.int64], NDArray[np.int64]], span: tuple[int, int],
           digits: tuple[int, int]) -> bool:
    """Stable LSD radix sort of ``src[lo:hi]`` (``buffers = (src, dst)``, ``span = (lo,
    hi)``) by ``bits`` bits of the values from bit ``low`` (``digits = (low, bits)``),
    digits of at most 12 bits; True when the sorted run ended in ``dst``."""
    src, dst = buffers
    (lo, hi), (low, bits) = span, digits
    passes = max(1, -(-bits // 12))
    width = -(-max(bits, 1) // passes)
    mask = (1 << width) - 1
    count = np.zeros((passes, (1 << width) + 1), dtype=np.int64)
    for i in range(lo, hi):
        for p in range(passes):
            count[p, ((src[i] >> (low + p * width)) & mask) + 1] += 1
    for p in range(passes):
        at = count[p]
        for d in range(1 << width):
            at[d + 1] += at[d]
        for i in range(lo, hi):
            d = (src[i] >> (low + p * width)) & mask
            dst[lo + at[d]] = src[i]
            at[d] += 1
        src, dst = dst, src
    return passes % 2 == 1


@numba.njit(cache=True, parallel=True)
def _radix_split(out: NDArray[np.int64], scratch: NDArray[np.int64], shift: int, bits: int) -> None:
    """:func:`_radix` of all of ``out`` by the key's top 6 bits into ``scratch`` (the 64
    runs of the walk's split level), then of each run by the other bits on every thread
    (``out`` the other buffer)."""
    top = shift + bits - 6
    _radix((out, scratch), (0, out.size), (top, 6))
    starts = np.searchsorted(scratch, np.arange(65) << top)  # runs in order of their bits
    starts[64] = out.size
    for b in numba.prange(64):
        _radix((scratch, out), (starts[b], starts[b + 1]), (shift, bits - 6))


def _sort_packed(out: NDArray[np.int64], bits: int, shift: int,
                 scratch: NDArray[np.int64]) -> NDArray[np.int64]:
    """Packed keys ``out`` (:func:`_pack`) sorted; the sorted array is ``out`` or
    ``scratch``. Small inputs: numpy's sort; a cloud: the top 6 bits first, then their
    runs side by side; else one radix sort."""
    if out.size < _RADIX_MIN:
        out.sort()
        return out
    if out.size >= CLOUD_MIN and bits > 6 and numba.get_num_threads() > 1:
        _radix_split(out, scratch, shift, bits)
        return scratch if -(-(bits - 6) // 12) % 2 == 0 else out
    return scratch if _radix((out, scratch), (0, out.size), (shift, bits)) else out


def sort_points(keys: NDArray[np.int64], values: NDArray[np.float64], bits: int, *,
                reuse_keys: bool = False) -> Sorted:
    """Points with finest ``keys`` (below ``2**bits``) and (N, nv) ``values``, stably
    sorted by key: packed with their index when both fit in 63 bits, else by
    ``_cellstats.sort_keys`` with the values put in that order. ``reuse_keys``: the
    caller gives up ``keys`` (int64, contiguous), whose buffer then holds packed keys."""
    keys = np.asarray(keys, np.int64)
    values = np.ascontiguousarray(values, np.float64)
    shift = max(1, (keys.size - 1).bit_length())
    if bits + shift > 63:
        sorted_keys, order = sort_keys(keys, bits)
        return sorted_keys, 0, values[order]
    own = reuse_keys and keys.flags.c_contiguous and keys.flags.writeable
    out, scratch = keys if own else np.empty(keys.size, np.int64), np.empty(keys.size, np.int64)
    with threads_for(keys.size, CLOUD_MIN):
        _pack(keys, shift, out, scratch)
    return _sort_packed(out, bits, shift, scratch), shift, values
