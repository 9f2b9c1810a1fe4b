"""3D cells as int64 keys (x, y, z indices packed in 21 bits each) and sparse tables of
point counts over them: the state of 3D-ALTE, one sorted table per level."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

__all__ = ["BITS", "KEY_MASK", "Z_OFFSET", "child_keys", "merge_counts", "pack_keys",
           "unpack_keys"]

#: Bits per axis of a key.
BITS = 21
#: Largest index on an axis.
KEY_MASK = (1 << BITS) - 1
#: Added to a fixed-altitude layer index, so that layers below the domain keep a valid key.
Z_OFFSET = 1 << (BITS - 1)


def pack_keys(ix: NDArray[np.int64], iy: NDArray[np.int64],
              iz: NDArray[np.int64]) -> NDArray[np.int64]:
    """One int64 key per cell from its integer indices, BITS bits each."""
    keys: NDArray[np.int64] = (ix << (2 * BITS)) | (iy << BITS) | iz
    return keys


def unpack_keys(keys: NDArray[np.int64],
                ) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.int64]]:
    """The integer indices of the cells ``keys``."""
    return keys >> (2 * BITS), (keys >> BITS) & KEY_MASK, keys & KEY_MASK


def child_keys(keys: NDArray[np.int64], variant: str) -> NDArray[np.int64]:
    """The sorted keys of the cells' children: eight, or four in x/y (``fixed_altitude``)."""
    ix, iy, iz = unpack_keys(keys)
    if variant == "fixed_altitude":
        offsets = [(dx, dy, 0) for dx in (0, 1) for dy in (0, 1)]
        kids = [pack_keys(2 * ix + dx, 2 * iy + dy, iz) for dx, dy, _ in offsets]
    else:
        kids = [pack_keys(2 * ix + (c & 1), 2 * iy + (c >> 1 & 1), 2 * iz + (c >> 2 & 1))
                for c in range(8)]
    return np.sort(np.concatenate(kids))


def merge_counts(keys: NDArray[np.int64], counts: NDArray[np.int64], new_keys: NDArray[np.int64],
           new_counts: NDArray[np.intp]) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """Add ``new_counts`` at sorted unique ``new_keys`` into the sorted table."""
    pos = np.searchsorted(keys, new_keys)
    found = pos < keys.size
    found[found] = keys[pos[found]] == new_keys[found]
    counts[pos[found]] += new_counts[found]
    fresh = ~found
    if fresh.any():
        keys = np.insert(keys, pos[fresh], new_keys[fresh])
        counts = np.insert(counts, pos[fresh], new_counts[fresh])
    return keys, counts
