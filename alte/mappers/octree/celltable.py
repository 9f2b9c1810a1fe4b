"""3D cells as int64 keys (x, y, z indices packed in 21 bits each) and sparse tables of
point counts over them: the state of 3D-ALTE, one sorted table per level."""

from __future__ import annotations

import numpy as np

__all__ = ["BITS", "KEY_MASK", "Z_OFFSET", "child_keys", "merge_counts", "pack_keys",
           "unpack_keys"]

#: Bits per axis of a key.
BITS = 21
#: Largest index on an axis.
KEY_MASK = (1 << BITS) - 1
#: Added to a fixed-altitude layer index, so that layers below the domain keep a valid key.
Z_OFFSET = 1 << (BITS - 1)


def pack_keys(ix: np.ndarray, iy: np.ndarray, iz: np.ndarray) -> np.ndarray:
    """One int64 key per cell from its integer indices, BITS bits each."""
    keys: np.ndarray = (ix << (2 * BITS)) | (iy << BITS) | iz
    return keys


def unpack_keys(keys: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The integer indices of the cells ``keys``."""
    return keys >> (2 * BITS), (keys >> BITS) & KEY_MASK, keys & KEY_MASK


def child_keys(keys: np.ndarray, variant: str) -> np.ndarray:
    """The sorted keys of the cells' children: eight, or four in x/y (``fixed_altitude``)."""
    ix, iy, iz = unpack_keys(keys)
    if variant == "fixed_altitude":
        offsets = [(dx, dy, 0) for dx in (0, 1) for dy in (0, 1)]
        kids = [pack_keys(2 * ix + dx, 2 * iy + dy, iz) for dx, dy, _ in offsets]
    else:
        kids = [pack_keys(2 * ix + (c & 1), 2 * iy + (c >> 1 & 1), 2 * iz + (c >> 2 & 1))
                for c in range(8)]
    return np.sort(np.concatenate(kids))


def merge_counts(keys: np.ndarray, counts: np.ndarray, new_keys: np.ndarray,
           new_counts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
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
