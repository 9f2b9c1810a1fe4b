"""Sparse voxel storage, pruning and the ``.bt`` format for the native Octomap.

The map is, per finest (depth-16) voxel ever observed, a float32 log-odds, kept in
8x8x8 blocks found by hashing their Morton code (:class:`VoxelStore`). Memory
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
from numba.cpython.unsafe.numbers import trailing_zeros

from alte.errors import MapperError
from alte.mappers._blockset import EMPTY, WORDS, find_slot, rehash
from alte.mappers._raycast import TREE_DEPTH, TREE_MAX_VAL, morton_decode

#: The voxel store: hash slots, their rows, block ids and float32 log-odds pages.
Store = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]

__all__ = ["PAGE", "Leaves", "VoxelStore", "check_origin", "leaf_geometry", "prune",
           "prune_voxels", "write_bt"]

_THREE = np.uint64(3)


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


#: Blocks per page of log-odds (1024 x 512 float32 = 2 MiB): the map grows a page at a
#: time, so no insert ever copies the map.
PAGE = 1024
_PAGE_SHIFT = 10


def _page() -> np.ndarray:
    return np.full((PAGE, 512), np.nan, dtype=np.float32)


class VoxelStore:
    """Per-voxel float32 log-odds in 8x8x8 blocks (NaN = never observed).

    A hash table maps a block's Morton code (key >> 9) to a row; rows live in
    fixed-size pages, so adding blocks never moves the map, and a scan's update
    (:func:`alte.mappers._raycast.scan_blocks`) is applied block by block: one probe
    per block, one clamped float32 add per voxel, as OctoMap's ``updateNodeLogOdds``.
    Blocks of the observed volume are mostly full (75 % on sim_nav_1 at 0.2 m), so
    this takes less memory than a key and a value per voxel. :meth:`fold` gives the
    observed voxels as one sorted key array and their values.
    """

    def __init__(self) -> None:
        self._slots = np.full(1 << 10, EMPTY, dtype=np.uint64)
        self._rows = np.zeros(1 << 10, dtype=np.int64)
        self._blocks = np.zeros(PAGE, dtype=np.uint64)
        self._pages = numba.typed.List([_page()])
        self._n = 0
        self._folded: tuple[np.ndarray, np.ndarray] | None = None

    def __len__(self) -> int:
        """Observed voxels."""
        return int(self.fold()[0].size)

    @property
    def blocks(self) -> int:
        """Blocks in use."""
        return self._n

    @property
    def nbytes(self) -> int:
        """Bytes of the blocks in use (512 log-odds and a code each) and of the hash
        table; the unused rest of the last page is not counted."""
        return int(self._n * (512 * 4 + 8) + self._slots.nbytes + self._rows.nbytes)

    def _reserve(self, need: int) -> None:
        total = self._n + need
        while total > len(self._pages) * PAGE:
            self._pages.append(_page())
        if total > self._blocks.size:
            grown = np.zeros(max(total, 2 * self._blocks.size), dtype=np.uint64)
            grown[:self._n] = self._blocks[:self._n]
            self._blocks = grown
        if 2 * total > self._slots.size:
            size = self._slots.size
            while 2 * total > size:
                size *= 2
            self._slots, self._rows = rehash(self._slots, self._blocks, self._n, size)

    def update(self, blocks: np.ndarray, bits: np.ndarray, miss: np.float32, hit: np.float32,
               clamp: tuple[np.float32, np.float32]) -> None:
        """Add ``miss`` at the free bits and ``hit`` at the occupied bits of each block
        (rows as :func:`~alte.mappers._raycast.scan_blocks` gives), clamped; a new voxel
        starts at log-odds 0 (OctoMap's new node)."""
        if blocks.size == 0:
            return
        self._reserve(blocks.size)
        store = (self._slots, self._rows, self._blocks, self._pages)
        model = (np.float32(miss), np.float32(hit), *clamp)
        self._n = _apply(store, self._n, (blocks, bits), model)
        self._folded = None

    def fold(self) -> tuple[np.ndarray, np.ndarray]:
        """Sorted Morton keys of the observed voxels and their log-odds (cached until the
        next update)."""
        if self._folded is None:
            self._folded = _collect(self._blocks, self._pages, self._n)
        return self._folded


@numba.njit(cache=True)
def _apply(store: Store, n: int, scan: tuple[np.ndarray, np.ndarray],
           model: tuple[np.float32, np.float32, np.float32, np.float32]) -> int:
    """Clamped float32 add of ``miss``/``hit`` at every set bit of the ``scan``'s blocks;
    ``model`` is (miss, hit, clamp low, clamp high); returns the new block count."""
    slots, rows, blocks, pages = store
    scan_blocks, scan_bits = scan
    miss, hit, lo, hi = model
    for r in range(scan_blocks.size):
        j = find_slot(slots, scan_blocks[r])
        if slots[j] == EMPTY:
            slots[j] = scan_blocks[r]
            rows[j] = n
            blocks[n] = scan_blocks[r]
            n += 1
        row = rows[j]
        page, at = pages[row >> _PAGE_SHIFT], row & (PAGE - 1)
        for w in range(2 * WORDS):
            word = scan_bits[r, w]
            update = miss if w < WORDS else hit
            base = (w % WORDS) * 64
            while word:
                i = base + trailing_zeros(word)  # type: ignore[call-arg]  # numba intrinsic
                word &= word - np.uint64(1)
                value = page[at, i]
                if np.isnan(value):
                    value = np.float32(0.0)
                page[at, i] = min(max(value + update, lo), hi)
    return n


@numba.njit(cache=True)
def _collect(blocks: np.ndarray, pages: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Observed voxels in Morton order: blocks sorted, voxels by local index within."""
    count = 0
    for row in range(n):
        count += 512 - np.isnan(pages[row >> _PAGE_SHIFT][row & (PAGE - 1)]).sum()
    keys = np.empty(count, dtype=np.uint64)
    values = np.empty(count, dtype=np.float32)
    k = 0
    for row in np.argsort(blocks[:n]):
        values_row = pages[row >> _PAGE_SHIFT][row & (PAGE - 1)]
        base = blocks[row] << np.uint64(9)
        for i in range(512):
            if not np.isnan(values_row[i]):
                keys[k] = base | np.uint64(i)
                values[k] = values_row[i]
                k += 1
    return keys, values


def _collapse(keys: np.ndarray, values: np.ndarray, depth: int) -> tuple[Leaves, Leaves]:
    """One depth of pruning over sorted ``keys``: the leaves kept at ``depth`` and the
    parents (at ``depth - 1``) whose 8 children all hold the same value."""
    parent = keys >> _THREE
    starts = np.flatnonzero(np.r_[True, parent[1:] != parent[:-1]])
    counts = np.diff(np.r_[starts, parent.size])
    vmin = np.minimum.reduceat(values, starts)
    collapse = (counts == 8) & (vmin == np.maximum.reduceat(values, starts))
    keep = ~np.repeat(collapse, counts)
    kept = keys[keep]
    return (Leaves(kept, np.full(kept.size, depth, dtype=np.int64), values[keep]),
            Leaves(parent[starts[collapse]], np.empty(0, np.int64), vmin[collapse]))


def _joined(out: list[Leaves]) -> Leaves:
    return Leaves(np.concatenate([lv.prefix for lv in out]),
                  np.concatenate([lv.depth for lv in out]).astype(np.int64),
                  np.concatenate([lv.value for lv in out]))


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
        kept, carry = _collapse(keys, values, depth)
        out.append(kept)
    return _joined(out)


def prune_voxels(keys: np.ndarray, values: np.ndarray) -> Leaves:
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
