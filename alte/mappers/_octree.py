"""Sparse voxel storage, pruning and the ``.bt`` format for the native Octomap.

The map is, per finest (depth-16) voxel ever observed, a 48-bit Morton key
(uint64) and a float32 log-odds, kept in a few sorted runs (:class:`VoxelStore`). Memory
therefore grows with the observed volume, never with the bounding box. OctoMap's
pruned tree is a lossless compression of exactly this per-voxel state (a node
collapses when its 8 children are leaves with bit-identical log-odds, and expands
again with the same value on the next update), so leaves, leaf counts and the
``.bt`` file are derived from the arrays on demand by :func:`prune`.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numba
import numpy as np

from alte.errors import MapperError
from alte.mappers._raycast import TREE_DEPTH, TREE_MAX_VAL, morton_decode

__all__ = ["Leaves", "VoxelStore", "check_origin", "leaf_geometry", "prune", "write_bt"]

_THREE = np.uint64(3)
#: A run is merged into the run below it once it holds at least 1/_RATIO of its voxels.
_RATIO = 2


@dataclass(frozen=True)
class Leaves:
    """Leaves of a pruned octree: Morton prefix at its ``depth``, and a value."""

    prefix: np.ndarray
    depth: np.ndarray
    value: np.ndarray

    def __len__(self) -> int:
        return int(self.prefix.size)


def check_origin(origin: object, owner: str) -> np.ndarray:
    """Return a finite float64 (3,) sensor origin or raise :class:`MapperError`."""
    arr = np.asarray(origin, dtype=np.float64)
    if arr.shape != (3,):
        raise MapperError(f"{owner}: origin must have shape (3,), got {arr.shape}")
    if not np.isfinite(arr).all():
        raise MapperError(f"{owner}: origin contains NaN or inf values")
    return arr


class VoxelStore:
    """Per-voxel float32 log-odds as a stack of sorted, disjoint Morton-key runs.

    One sorted array would copy the whole map to insert each scan's new voxels.
    Instead every scan's new voxels become a small run on top of the stack, and a
    run is merged into the one below it while it holds at least 1/``_RATIO`` as
    many voxels (like Timsort's run stack): run sizes fall geometrically, so there
    are O(log n) runs and each voxel is merged O(log n) times. Existing voxels are
    found by a galloping search and updated in place, so the state is exactly that of
    one sorted array, which :meth:`fold` returns.
    """

    def __init__(self) -> None:
        self._runs: list[tuple[np.ndarray, np.ndarray]] = []

    def __len__(self) -> int:
        return sum(int(keys.size) for keys, _ in self._runs)

    def update(
        self, update_keys: np.ndarray, updates: np.ndarray, clamp: tuple[np.float32, np.float32]
    ) -> None:
        """Add float32 ``updates`` at sorted unique ``update_keys``, clamped like
        ``updateNodeLogOdds``; new voxels start at log-odds 0 (OctoMap's new node)."""
        lo, hi = clamp
        todo = np.arange(update_keys.size)
        for keys, values in self._runs:
            if todo.size == 0:
                return
            found = _update_run(keys, values, update_keys[todo], updates[todo], clamp)
            todo = todo[~found]
        if todo.size == 0:
            return
        fresh = np.clip(np.float32(0.0) + updates[todo], lo, hi).astype(np.float32)
        self._runs.append((update_keys[todo], fresh))
        while len(self._runs) > 1 and self._runs[-1][0].size * _RATIO >= self._runs[-2][0].size:
            upper = self._runs.pop()
            self._runs.append(_merge(*self._runs.pop(), *upper))

    def fold(self) -> tuple[np.ndarray, np.ndarray]:
        """Merge all runs into one; return its sorted keys and log-odds (live arrays)."""
        while len(self._runs) > 1:
            upper = self._runs.pop()
            self._runs.append(_merge(*self._runs.pop(), *upper))
        if not self._runs:
            return np.empty(0, dtype=np.uint64), np.empty(0, dtype=np.float32)
        return self._runs[0]


@numba.njit(cache=True, inline="always")
def _gallop(keys: np.ndarray, key: np.uint64, start: int) -> int:
    """First index >= ``start`` with ``keys[index] >= key``: doubling steps, then bisection.

    Sorted, clustered queries searched from the previous answer cost O(log gap) each.
    """
    step = 1
    while start + step < keys.size and keys[start + step] < key:
        step *= 2
    low, high = start + step // 2, min(start + step, keys.size)
    while low < high:
        mid = (low + high) // 2
        if keys[mid] < key:
            low = mid + 1
        else:
            high = mid
    return low


@numba.njit(cache=True)
def _update_run(
    keys: np.ndarray, values: np.ndarray, query: np.ndarray, updates: np.ndarray,
    clamp: tuple[np.float32, np.float32],
) -> np.ndarray:
    """Clamped in-place add of ``updates`` at the sorted ``query`` keys present in ``keys``;
    returns which queries were found."""
    found = np.zeros(query.size, dtype=np.bool_)
    at = 0
    for j in range(query.size):
        at = _gallop(keys, query[j], at)
        if at < keys.size and keys[at] == query[j]:
            found[j] = True
            value = values[at] + updates[j]
            values[at] = min(max(value, clamp[0]), clamp[1])
    return found


@numba.njit(cache=True)
def _merge(
    keys_a: np.ndarray, values_a: np.ndarray, keys_b: np.ndarray, values_b: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Linear merge of two sorted, disjoint key runs with their values."""
    size_a, size_b = keys_a.size, keys_b.size
    keys = np.empty(size_a + size_b, dtype=np.uint64)
    values = np.empty(size_a + size_b, dtype=np.float32)
    i = j = 0
    for k in range(size_a + size_b):
        if j == size_b or (i < size_a and keys_a[i] < keys_b[j]):
            keys[k], values[k] = keys_a[i], values_a[i]
            i += 1
        else:
            keys[k], values[k] = keys_b[j], values_b[j]
            j += 1
    return keys, values


def prune(leaves: Leaves) -> Leaves:
    """Collapse every node whose 8 children are leaves with equal values, bottom-up.

    Starting from depth-16 voxels this gives the canonical fully pruned tree that
    OctoMap's on-the-fly ``pruneNode`` maintains; starting from mixed-depth leaves
    with boolean values it is ``toMaxLikelihood`` followed by ``prune``.
    """
    out = []
    carry = Leaves(np.empty(0, np.uint64), np.empty(0, np.int64), leaves.value[:0])
    for depth in range(TREE_DEPTH, -1, -1):
        at = leaves.depth == depth
        keys = np.concatenate([leaves.prefix[at], carry.prefix])
        values = np.concatenate([leaves.value[at], carry.value])
        order = np.argsort(keys, kind="stable")
        keys, values = keys[order], values[order]
        if depth == 0 or keys.size == 0:
            out.append(Leaves(keys, np.full(keys.size, depth), values))
            carry = Leaves(keys[:0], np.empty(0, np.int64), values[:0])
            continue
        parent = keys >> _THREE
        starts = np.flatnonzero(np.r_[True, parent[1:] != parent[:-1]])
        counts = np.diff(np.r_[starts, parent.size])
        vmin = np.minimum.reduceat(values, starts)
        collapse = (counts == 8) & (vmin == np.maximum.reduceat(values, starts))
        keep = ~np.repeat(collapse, counts)
        out.append(Leaves(keys[keep], np.full(int(keep.sum()), depth), values[keep]))
        carry = Leaves(parent[starts[collapse]], np.empty(0, np.int64), vmin[collapse])
    return Leaves(
        np.concatenate([lv.prefix for lv in out]),
        np.concatenate([lv.depth for lv in out]).astype(np.int64),
        np.concatenate([lv.value for lv in out]),
    )


def leaf_geometry(leaves: Leaves, voxel: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Minimum depth-16 key (K, 3), side in voxels (K,) and centre in metres (K, 3)."""
    shift = (TREE_DEPTH - leaves.depth).astype(np.uint64)
    min_keys = morton_decode(leaves.prefix << (_THREE * shift))
    side = np.left_shift(1, TREE_DEPTH - leaves.depth)
    centers = (min_keys - TREE_MAX_VAL + side[:, None] / 2.0) * voxel
    return min_keys, side, centers


def _inner_nodes(leaves: Leaves) -> list[np.ndarray]:
    """Sorted Morton prefixes of the inner nodes at each depth (index = depth)."""
    inner: list[np.ndarray] = [np.empty(0, np.uint64) for _ in range(TREE_DEPTH + 1)]
    for depth in range(TREE_DEPTH, 0, -1):
        here = np.concatenate([leaves.prefix[leaves.depth == depth], inner[depth]])
        inner[depth - 1] = np.unique(here >> _THREE)
    return inner


def _child_codes(leaves: Leaves, occupied: np.ndarray,
                 inner: list[np.ndarray]) -> list[np.ndarray]:
    """16-bit child descriptor of each inner node: 2 bits per child (1 free, 2 occ, 3 inner)."""
    codes: list[np.ndarray] = []
    for depth in range(TREE_DEPTH):
        parents = inner[depth]
        at = leaves.depth == depth + 1
        kids = np.concatenate([leaves.prefix[at], inner[depth + 1]])
        kind = np.concatenate([np.where(occupied[at], 2, 1), np.full(inner[depth + 1].size, 3)])
        slot = (kids & np.uint64(7)).astype(np.int64)
        owner = np.searchsorted(parents, kids >> _THREE)
        bits = np.bincount(owner, weights=kind << (2 * slot), minlength=parents.size)
        codes.append(bits.astype(np.uint16))
    return codes


def write_bt(path: Path, leaves: Leaves, occupied: np.ndarray, voxel: float) -> int:
    """Write OctoMap's maximum-likelihood binary tree; return the number of nodes.

    Like ``OcTree::writeBinary``, values are first reduced to occupied/free and the
    tree re-pruned on that binary state. Inner nodes are written depth-first
    (children in index order, x = bit 0, y = bit 1, z = bit 2), each as two bytes:
    children 0-3 then 4-7, 2 bits per child (01 free, 10 occupied, 11 has children).
    """
    ml = prune(Leaves(leaves.prefix, leaves.depth, np.asarray(occupied, dtype=bool)))
    inner = _inner_nodes(ml) if len(ml) and not (ml.depth == 0).all() else []
    n_nodes = len(ml) + sum(int(level.size) for level in inner)
    header = (
        "# Octomap OcTree binary file\n"
        "# (feel free to add / change comments, but leave the first line as it is!)\n#\n"
        f"id OcTree\nsize {n_nodes}\nres {voxel!r}\ndata\n"
    )
    payload = b""
    if inner:
        codes = _child_codes(ml, ml.value, inner)
        depth = np.concatenate([np.full(lv.size, d) for d, lv in enumerate(inner[:-1])])
        prefix = np.concatenate(inner[:-1])
        first_voxel = prefix << (_THREE * (TREE_DEPTH - depth).astype(np.uint64))
        order = np.lexsort((depth, first_voxel))
        payload = np.concatenate(codes)[order].astype("<u2").tobytes()
    with open(path, "wb") as handle:
        handle.write(header.encode("ascii"))
        handle.write(payload)
    return n_nodes
