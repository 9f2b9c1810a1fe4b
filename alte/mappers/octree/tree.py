"""Pruning and the ``.bt`` format for the native Octomap.

The map is, per finest (depth-16) voxel ever observed, a float32 log-odds
(:class:`alte.mappers.octomap.voxelstore.VoxelStore`). OctoMap's pruned tree is a lossless
compression of exactly this per-voxel state (a node collapses when its 8 children are
leaves with bit-identical log-odds, and expands again with the same value on the next
update), so leaves, leaf counts and the ``.bt`` file are derived from the sorted
voxels on demand by :func:`prune`.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Generic, TypeVar

import numba
import numpy as np
from numpy.typing import NDArray

from alte.errors import MapperError
from alte.mappers.octree.raycast import TREE_DEPTH, TREE_MAX_VAL, _compact, morton_decode

__all__ = ["Leaves", "check_origin", "leaf_boxes", "leaf_geometry", "prune", "prune_voxels",
           "write_bt"]

_THREE = np.uint64(3)
#: A leaf's value: float32 log-odds, or the occupied flag of a maximum-likelihood tree.
_V = TypeVar("_V", np.float32, np.bool_)
#: Either value of a leaf, where numba compiles one kernel for both (its dispatcher takes
#: no type variables).
_Values = NDArray[np.float32 | np.bool_]


@dataclass(frozen=True)
class Leaves(Generic[_V]):
    """Leaves of a pruned octree: Morton prefix at its ``depth``, and a value."""

    prefix: NDArray[np.uint64]
    depth: NDArray[np.int64]
    value: NDArray[_V]

    def __len__(self) -> int:
        return int(self.prefix.size)


def check_origin(origin: object, owner: str) -> NDArray[np.float64]:
    """Return a finite float64 (3,) sensor origin or raise :class:`MapperError`."""
    arr = np.asarray(origin, dtype=np.float64)
    if arr.shape != (3,):
        raise MapperError(f"{owner}: origin must have shape (3,), got {arr.shape}")
    if not np.isfinite(arr).all():
        raise MapperError(f"{owner}: origin contains NaN or inf values")
    return arr


@numba.njit(cache=True)
def _collapse_sorted(keys: NDArray[np.uint64], values: _Values
                     ) -> tuple[NDArray[np.uint64], _Values, NDArray[np.uint64], _Values]:
    """One pass over sorted keys: (kept keys, their values, parents whose 8 children all
    hold the same value, that value). Arrays allocated here, untouched beyond use."""
    n = keys.shape[0]
    kept_k, kept_v = np.empty(n, keys.dtype), np.empty(n, values.dtype)
    par_k, par_v = np.empty(n // 8 + 1, keys.dtype), np.empty(n // 8 + 1, values.dtype)
    kept = parents = 0
    i = 0
    while i < n:
        parent = keys[i] >> np.uint64(3)
        j = i + 1
        low = high = values[i]
        while j < n and keys[j] >> np.uint64(3) == parent:
            low, high = min(low, values[j]), max(high, values[j])
            j += 1
        if j - i == 8 and low == high:
            par_k[parents], par_v[parents] = parent, low
            parents += 1
        else:
            for t in range(i, j):
                kept_k[kept], kept_v[kept] = keys[t], values[t]
                kept += 1
        i = j
    return kept_k[:kept], kept_v[:kept], par_k[:parents], par_v[:parents]


def _collapse(keys: NDArray[np.uint64], values: NDArray[_V], depth: int
              ) -> tuple[Leaves[_V], Leaves[_V]]:
    """One depth of pruning over sorted ``keys``: the leaves kept at ``depth`` and the
    parents (at ``depth - 1``) whose 8 children all hold the same value."""
    kept, kept_values, parents, parent_values = _collapse_sorted(
        np.ascontiguousarray(keys, np.uint64), np.ascontiguousarray(values))
    return (Leaves(kept, np.full(kept.size, depth, dtype=np.int64),
                   np.asarray(kept_values, dtype=values.dtype)),
            Leaves(parents, np.empty(0, np.int64), np.asarray(parent_values, dtype=values.dtype)))


def _joined(out: list[Leaves[_V]]) -> Leaves[_V]:
    return Leaves(np.concatenate([lv.prefix for lv in out]),
                  np.concatenate([lv.depth for lv in out]).astype(np.int64, copy=False),
                  np.concatenate([lv.value for lv in out]))


def prune(leaves: Leaves[_V]) -> Leaves[_V]:
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
        kept, carry = _collapse(keys, values, depth)
        out.append(kept)
    return _joined(out)


def prune_voxels(keys: NDArray[np.uint64], values: NDArray[np.float32]) -> Leaves[np.float32]:
    """:func:`prune` of sorted, unique depth-16 voxels (what the store folds to).

    With no leaves above depth 16 the nodes of each depth are exactly the collapsed
    parents of the depth below, already sorted: no per-depth concatenation or sort,
    so the peak memory of pruning a flight's tens of millions of voxels stays a few
    copies of the key array instead of a dozen.
    """
    out = []
    nodes = Leaves(keys, np.empty(0, np.int64), values)
    for depth in range(TREE_DEPTH, 0, -1):
        if len(nodes) == 0:
            break
        kept, nodes = _collapse(nodes.prefix, nodes.value, depth)
        out.append(kept)
    out.append(Leaves(nodes.prefix, np.zeros(len(nodes), np.int64), nodes.value))
    return _joined(out)


@numba.njit(cache=True)
def _boxes(prefix: NDArray[np.uint64], depth: NDArray[np.int64], voxel: float
           ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Centres and sizes (metres) of leaves, one pass: :func:`leaf_geometry`'s centres and
    ``side * voxel`` per axis, the same operations without its temporaries."""
    n = prefix.shape[0]
    centers, sizes = np.empty((n, 3)), np.empty((n, 3))
    for i in range(n):
        shift = np.uint64(TREE_DEPTH - depth[i])
        code = prefix[i] << (np.uint64(3) * shift)
        side = 1 << (TREE_DEPTH - depth[i])
        half = side / 2.0
        size = side * voxel
        for a in range(3):
            key = np.int64(_compact(code >> np.uint64(a)))
            centers[i, a] = ((key - TREE_MAX_VAL) + half) * voxel
            sizes[i, a] = size
    return centers, sizes


def leaf_boxes(leaves: Leaves[_V], voxel: float) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Centre (K, 3) and size (K, 3) of each leaf in metres."""
    return _boxes(np.ascontiguousarray(leaves.prefix, np.uint64),
                  np.ascontiguousarray(leaves.depth, np.int64), float(voxel))


def leaf_geometry(leaves: Leaves[_V], voxel: float,
                  ) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.float64]]:
    """Minimum depth-16 key (K, 3), side in voxels (K,) and centre in metres (K, 3)."""
    shift = (TREE_DEPTH - leaves.depth).astype(np.uint64)
    min_keys = morton_decode(leaves.prefix << (_THREE * shift))
    side = np.left_shift(1, TREE_DEPTH - leaves.depth)
    centers = (min_keys - TREE_MAX_VAL + side[:, None] / 2.0) * voxel
    return min_keys, side, centers


def _inner_nodes(leaves: Leaves[np.bool_]) -> list[NDArray[np.uint64]]:
    """Sorted Morton prefixes of the inner nodes at each depth (index = depth)."""
    inner: list[NDArray[np.uint64]] = [np.empty(0, np.uint64) for _ in range(TREE_DEPTH + 1)]
    for depth in range(TREE_DEPTH, 0, -1):
        here = np.concatenate([leaves.prefix[leaves.depth == depth], inner[depth]])
        inner[depth - 1] = np.unique(here >> _THREE)
    return inner


def _child_codes(leaves: Leaves[np.bool_], occupied: NDArray[np.bool_],
                 inner: list[NDArray[np.uint64]]) -> list[NDArray[np.uint16]]:
    """16-bit child descriptor of each inner node: 2 bits per child (1 free, 2 occ, 3 inner)."""
    codes: list[NDArray[np.uint16]] = []
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


def write_bt(path: Path, leaves: Leaves[np.float32], occupied: NDArray[np.bool_],
             voxel: float) -> int:
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
