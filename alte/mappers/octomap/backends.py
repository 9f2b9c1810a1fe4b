"""The two Octomap backends behind :class:`alte.mappers.octomap.Octomap`.

``NativeTree`` is our implementation (numba ray casting into blocks of voxels);
``ReferenceTree`` wraps the C++ OctoMap library through ``pyoctomap``. Both offer
the same small interface so the mapper and :func:`compare_backends` treat them alike.
"""

from __future__ import annotations

import tempfile
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from typing import TYPE_CHECKING, Protocol

import numpy as np
from numpy.typing import NDArray

from alte.mappers.octomap.cost import scan_cost
from alte.mappers.octomap.scan import ScanWork, scan_blocks
from alte.mappers.octomap.voxelstore import VoxelStore
from alte.mappers.octree.blockset import WORDS, keys_to_blocks
from alte.mappers.octree.raycast import TREE_DEPTH, TREE_MAX_VAL, morton_decode, morton_encode
from alte.mappers.octree.tree import Leaves, prune_voxels, write_bt

if TYPE_CHECKING:
    import pyoctomap

__all__ = ["NativeTree", "OcTreeLike", "ReferenceTree", "SensorModel", "logodds", "tree_leaves",
           "voxel_keys"]

_THREE = np.uint64(3)


def logodds(p: float) -> np.float32:
    """OctoMap's ``logodds``: computed in double, stored as float."""
    return np.float32(np.log(p / (1.0 - p)))


@dataclass(frozen=True)
class SensorModel:
    """OctoMap's sensor model: hit/miss probabilities, clamping bounds, occupancy threshold.

    The trees work in float32 log-odds: :attr:`hit`, :attr:`miss`, :attr:`clamp` and
    :attr:`occupied`.
    """

    prob_hit: float
    prob_miss: float
    clamp_min: float
    clamp_max: float
    occupancy_threshold: float

    @cached_property
    def hit(self) -> np.float32:
        return logodds(self.prob_hit)

    @cached_property
    def miss(self) -> np.float32:
        return logodds(self.prob_miss)

    @cached_property
    def clamp(self) -> tuple[np.float32, np.float32]:
        return logodds(self.clamp_min), logodds(self.clamp_max)

    @cached_property
    def occupied(self) -> np.float32:
        return logodds(self.occupancy_threshold)


class _OcTreeNode(Protocol):
    def getLogOdds(self) -> float: ...  # noqa: N802 - pyoctomap's (OctoMap's) names


class _OcTreeLeaf(Protocol):
    current_node: _OcTreeNode

    def getCoordinate(self) -> Sequence[float]: ...  # noqa: N802
    def getDepth(self) -> int: ...  # noqa: N802


class OcTreeLike(Protocol):
    """What :func:`tree_leaves` reads of a ``pyoctomap.OcTree`` (untyped library)."""

    def begin_leafs(self) -> Iterable[_OcTreeLeaf]: ...
    def getResolution(self) -> float: ...  # noqa: N802


class NativeTree:
    """Per-voxel float32 log-odds in hashed 8x8x8 blocks (see ``_voxelstore.VoxelStore``)."""

    def __init__(self, voxel: float, max_range: float, model: SensorModel) -> None:
        self.voxel = voxel
        self.max_range = max_range
        self.model = model
        self.store = VoxelStore()
        self._leaves: Leaves[np.float32] | None = None
        self._work = ScanWork()
        self._hits = 0

    def insert_scan(self, points: NDArray[np.float64], origin: NDArray[np.float64]) -> None:
        """OctoMap ``insertPointCloud``: each voxel updated once, occupied beats free (one
        thread: the rays are walked four at a time in vector registers)."""
        blocks, bits = scan_blocks(points.astype(np.float32), origin.astype(np.float32),
                                   self.voxel, self.max_range, self._work)
        self._update(blocks, bits)

    def insert_hits(self, points: NDArray[np.float64]) -> None:
        """Mark the voxels holding ``points`` occupied once (no ray casting)."""
        keys = voxel_keys(points, self.voxel)
        self._hits += len(keys)
        self._update(*keys_to_blocks(keys, WORDS))

    @property
    def cost(self) -> int:
        """Ray steps of the scans (:func:`alte.mappers.octomap.cost.scan_cost`) and voxels hit."""
        return self._work.steps + self._hits

    def _update(self, blocks: NDArray[np.uint64], bits: NDArray[np.uint64]) -> None:
        model = self.model
        self.store.update(blocks, bits, model.miss, model.hit, model.clamp)
        self._leaves = None

    @property
    def keys(self) -> NDArray[np.uint64]:
        """Sorted Morton keys of every observed depth-16 voxel."""
        return self.store.fold()[0]

    @property
    def log_odds(self) -> NDArray[np.float32]:
        """Float32 log-odds of the voxels in :attr:`keys`."""
        return self.store.fold()[1]

    def leaves(self) -> Leaves[np.float32]:
        """Pruned leaves (cached until the next update)."""
        if self._leaves is None:
            self._leaves = prune_voxels(*self.store.fold())
        return self._leaves

    @property
    def num_leaves(self) -> int:
        return len(self.leaves())

    @property
    def memory_bytes(self) -> int:
        return self.store.nbytes

    def write_bt(self, path: Path) -> None:
        leaves = self.leaves()
        write_bt(path, leaves, leaves.value > self.model.occupied, self.voxel)


class ReferenceTree:
    """The C++ OctoMap (``pyoctomap.OcTree``) configured with the same sensor model."""

    def __init__(self, voxel: float, max_range: float, model: SensorModel) -> None:
        import pyoctomap

        self.voxel = voxel
        self.max_range = max_range
        self.model = model
        self.tree = pyoctomap.OcTree(self.voxel)
        _configure(self.tree, model)
        self.cost = 0

    def insert_scan(self, points: NDArray[np.float64], origin: NDArray[np.float64]) -> None:
        self.cost += scan_cost(points.astype(np.float32), origin.astype(np.float32),
                               self.voxel, self.max_range)
        self.tree.insertPointCloud(
            np.ascontiguousarray(points, dtype=np.float64),
            np.ascontiguousarray(origin, dtype=np.float64),
            self.max_range, lazy_eval=False, discretize=False,
        )

    def insert_hits(self, points: NDArray[np.float64]) -> None:
        keys = voxel_keys(points, self.voxel)
        self.cost += len(keys)
        centers = (morton_decode(keys) - TREE_MAX_VAL + 0.5) * self.voxel
        self.tree.updateNodes(centers, True)

    def leaves(self) -> Leaves[np.float32]:
        return tree_leaves(self.tree)

    @property
    def num_leaves(self) -> int:
        return int(self.tree.getNumLeafNodes())

    @property
    def memory_bytes(self) -> int:
        return int(self.tree.memoryUsage())

    def write_bt(self, path: Path) -> None:
        """``writeBinary`` on a copy: OctoMap converts the tree it writes to max-likelihood."""
        with tempfile.TemporaryDirectory() as tmp:
            full = str(Path(tmp) / "copy.ot")
            self.tree.write(full)
            copy = self.tree.read(full)
        _configure(copy, self.model)
        copy.writeBinary(str(path))


def _configure(tree: pyoctomap.OcTree, model: SensorModel) -> None:
    tree.setProbHit(model.prob_hit)
    tree.setProbMiss(model.prob_miss)
    tree.setClampingThresMin(model.clamp_min)
    tree.setClampingThresMax(model.clamp_max)
    tree.setOccupancyThres(model.occupancy_threshold)


def voxel_keys(points: NDArray[np.float64], voxel: float) -> NDArray[np.uint64]:
    """Sorted unique Morton keys of the voxels holding float32-rounded ``points``."""
    keys = np.floor(points.astype(np.float32).astype(np.float64) * (1.0 / voxel))
    keys = keys.astype(np.int64) + TREE_MAX_VAL
    inside = ((keys >= 0) & (keys < 2 * TREE_MAX_VAL)).all(axis=1)
    return np.unique(morton_encode(keys[inside]))


def tree_leaves(tree: OcTreeLike) -> Leaves[np.float32]:
    """Leaves of a ``pyoctomap.OcTree`` as Morton prefixes, depths and float32 log-odds.

    pyoctomap only offers a leaf iterator, so this is one Python step per leaf
    (about 1.5 us each): used for the reference backend and for reading ``.bt`` files.
    """
    rows = [
        (*leaf.getCoordinate(), leaf.getDepth(), leaf.current_node.getLogOdds())
        for leaf in tree.begin_leafs()
    ]
    table = np.asarray(rows, dtype=np.float64).reshape(-1, 5)
    depth = table[:, 3].astype(np.int64)
    voxel = tree.getResolution()
    keys = np.floor(table[:, :3] / voxel).astype(np.int64) + TREE_MAX_VAL
    prefix = morton_encode(keys) >> (_THREE * (TREE_DEPTH - depth).astype(np.uint64))
    order = np.argsort(prefix << (_THREE * (TREE_DEPTH - depth).astype(np.uint64)))
    return Leaves(prefix[order], depth[order], table[order, 4].astype(np.float32))
