"""An Octomap's pruned leaves as cells: centres, sizes, probability, occupied flag; the
voxels its occupied leaves cover; the cells of an OctoMap ``.bt`` file."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from alte.errors import MapperError
from alte.mappers.base import Cells
from alte.mappers.octomap.backends import tree_leaves
from alte.mappers.octree.raycast import TREE_DEPTH
from alte.mappers.octree.tree import Leaves, leaf_boxes

__all__ = ["leaf_subset", "leaves_to_cells", "occupied_voxels", "read_bt"]


def leaf_subset(leaves: Leaves[np.float32], mask: NDArray[np.bool_]) -> Leaves[np.float32]:
    """The leaves where ``mask`` is true."""
    return Leaves(leaves.prefix[mask], leaves.depth[mask], leaves.value[mask])


def leaves_to_cells(leaves: Leaves[np.float32], voxel: float,
                    occupied_log_odds: float | np.float32) -> Cells:
    """Cells of pruned leaves: centres, cubic sizes, probability, occupied flag, depth."""
    centers, sizes = leaf_boxes(leaves, voxel)
    value = 1.0 - 1.0 / (1.0 + np.exp(leaves.value.astype(np.float64)))
    return Cells(centers, sizes, value, leaves.value > occupied_log_odds, leaves.depth.copy())


def occupied_voxels(leaves: Leaves[np.float32], occupied_log_odds: float | np.float32
                    ) -> NDArray[np.uint64]:
    """Depth-16 Morton keys covered by occupied leaves (a leaf is a contiguous Morton range)."""
    occ = leaf_subset(leaves, leaves.value > occupied_log_odds)
    span = np.uint64(1) << (np.uint64(3) * (TREE_DEPTH - occ.depth).astype(np.uint64))
    first = occ.prefix * span
    counts = span.astype(np.int64)
    offsets = np.arange(counts.sum(), dtype=np.uint64) - np.repeat(
        np.cumsum(counts) - counts, counts
    ).astype(np.uint64)
    return np.sort(np.repeat(first, counts) + offsets)


def read_bt(path: str | Path) -> Cells:
    """Cells of an OctoMap ``.bt`` file, read with the reference library."""
    import pyoctomap

    source = Path(path)
    if not source.is_file():
        raise MapperError(f"octomap: {source} does not exist")
    tree = pyoctomap.OcTree(0.1)
    if not tree.readBinary(str(source)):
        raise MapperError(f"octomap: {source} is not a readable OctoMap binary tree (.bt)")
    voxel = tree.getResolution()
    threshold = np.float32(np.log(tree.getOccupancyThres() / (1 - tree.getOccupancyThres())))
    return leaves_to_cells(tree_leaves(tree), voxel, threshold)
