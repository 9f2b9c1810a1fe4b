"""The compiled pruning and leaf-box kernels of the native Octomap equal the numpy
expressions they replaced (kept here as oracles), bit for bit."""

from __future__ import annotations

import numpy as np

from alte.mappers.octree.raycast import TREE_DEPTH
from alte.mappers.octree.tree import Leaves, leaf_boxes, leaf_geometry, prune_voxels

_THREE = np.uint64(3)


def _collapse_numpy(keys, values, depth):
    parent = keys >> _THREE
    starts = np.flatnonzero(np.r_[True, parent[1:] != parent[:-1]])
    counts = np.diff(np.r_[starts, parent.size])
    vmin = np.minimum.reduceat(values, starts)
    collapse = (counts == 8) & (vmin == np.maximum.reduceat(values, starts))
    keep = ~np.repeat(collapse, counts)
    kept = keys[keep]
    return (Leaves(kept, np.full(kept.size, depth, dtype=np.int64), values[keep]),
            Leaves(parent[starts[collapse]], np.empty(0, np.int64), vmin[collapse]))


def _prune_numpy(keys, values):
    out = []
    nodes = Leaves(keys, np.empty(0, np.int64), values)
    for depth in range(TREE_DEPTH, 0, -1):
        if len(nodes) == 0:
            break
        kept, nodes = _collapse_numpy(nodes.prefix, nodes.value, depth)
        out.append(kept)
    out.append(Leaves(nodes.prefix, np.zeros(len(nodes), np.int64), nodes.value))
    return Leaves(np.concatenate([lv.prefix for lv in out]),
                  np.concatenate([lv.depth for lv in out]).astype(np.int64),
                  np.concatenate([lv.value for lv in out]))


def _voxels(seed: int) -> tuple[np.ndarray, np.ndarray]:
    """Sorted unique depth-16 voxels: whole blocks of equal values at several scales (they
    collapse), broken blocks, lone voxels."""
    rng = np.random.default_rng(seed)
    blocks = rng.choice(1 << 30, 3000, replace=False).astype(np.uint64)
    sizes = rng.integers(0, 4, 3000)  # 8**k voxels per block
    keys, values = [], []
    for block, k in zip(blocks, sizes, strict=True):
        n = 8 ** int(k)
        first = block << (_THREE * np.uint64(k))
        keys.append(first + np.arange(n, dtype=np.uint64))
        v = np.full(n, rng.choice([-2.0, -0.4, 0.85, 3.5]), np.float32)
        if rng.random() < 0.3:
            v[rng.integers(0, n)] += np.float32(0.4)  # one voxel differs: no collapse there
        values.append(v)
    keys_all = np.concatenate(keys)
    order = np.argsort(keys_all)
    keys_all, vals = keys_all[order], np.concatenate(values)[order]
    unique = np.r_[True, keys_all[1:] != keys_all[:-1]]
    return keys_all[unique], vals[unique]


def test_prune_equals_the_numpy_pruning():
    for seed in range(3):
        keys, values = _voxels(seed)
        ours, oracle = prune_voxels(keys, values), _prune_numpy(keys, values)
        assert ours.prefix.dtype == oracle.prefix.dtype and ours.value.dtype == oracle.value.dtype
        for field in ("prefix", "depth", "value"):
            assert np.array_equal(getattr(ours, field), getattr(oracle, field)), field
        assert len(ours) < len(keys)  # something collapsed
    empty = prune_voxels(np.empty(0, np.uint64), np.empty(0, np.float32))
    assert len(empty) == 0


def test_leaf_boxes_equal_leaf_geometry():
    keys, values = _voxels(5)
    leaves = prune_voxels(keys, values)
    for voxel in (0.1, 0.25, 1.0 / 3.0, 4.0):
        centers, sizes = leaf_boxes(leaves, voxel)
        _, side, expected = leaf_geometry(leaves, voxel)
        assert np.array_equal(centers, expected)
        assert np.array_equal(sizes, np.repeat((side * voxel)[:, None], 3, axis=1)
                              .astype(np.float64))
