"""The map refinement aligns each scan to, updated incrementally.

:class:`DenseMap` holds one point per ``voxel`` cell with a normal from its
:data:`NEIGHBOURS` nearest map neighbours. Scans are queued (on a ``voxel / 2`` grid) and join every
``rebuild`` scans: cells the map does not hold yet are appended (the mean of the queued
points in them); the points of a scan whose recorded pose was *confirmed* (kept for
lack of evidence against it, or the first) are also averaged into the cells already
held, while a *corrected* scan only extends the map: its pose came from the map, and
feeding it back would let the map drift with the alignments' errors (on the simulated
``exp_nav_2`` the refined positions then wander 8 cm from the truth instead of 4.5).
Normals are estimated for the new points and for the :data:`REFRESH` nearest map points
of each (their neighbourhood changed); the rest keep theirs. Cells beyond ``radius``
of the sensor are dropped and the k-d tree (small_gicp) rebuilt. An update costs the
k-d tree plus what is new, not grid, tree and normals of the whole map again. The
alignment to it is :mod:`~alte.registration.refalign`.
"""

from __future__ import annotations

import os
from typing import Protocol

import numpy as np
from numpy.typing import NDArray

__all__ = ["MAX_SOURCE", "NEIGHBOURS", "REACH", "DenseMap"]

#: Correspondence reach, in map voxels.
REACH = 4.0
#: Most points of a scan aligned (evenly spaced after the voxel grid): a few thousand
#: constrain six degrees of freedom as well as tens of thousands, at a fraction of the cost.
MAX_SOURCE = 5000
#: Map neighbours a normal is estimated from.
NEIGHBOURS = 20
#: A new map point's nearest neighbours whose normals are estimated again (their
#: neighbourhood changed): the frontier of what the map saw.
REFRESH = 5
#: Cell index range (each axis) packed into one int64 key: +-2^20 cells.
_HALF = 1 << 20


class GicpCloud(Protocol):
    """What is read of a small_gicp point cloud (small_gicp ships no types)."""

    def size(self) -> int: ...
    def points(self) -> NDArray[np.float64]: ...
    def normals(self) -> NDArray[np.float64]: ...


class _GicpTree(Protocol):
    """What is read of a small_gicp k-d tree."""

    def batch_nearest_neighbor_search(self, pts: NDArray[np.float64], num_threads: int = 1,
                                      ) -> tuple[list[int], list[float]]: ...
    def batch_knn_search(self, pts: NDArray[np.float64], k: int, num_threads: int = 1,
                         ) -> tuple[NDArray[np.int64], NDArray[np.float64]]: ...


def _threads(wanted: int) -> int:
    return wanted if wanted > 0 else max(1, os.cpu_count() or 1)


def _codes(points: NDArray[np.float64], voxel: float) -> NDArray[np.int64]:
    """One int64 per point: its cell ``floor(p / voxel)`` packed (21 bits per axis; cells
    beyond +-2^20 wrap, which only merges cells millions of voxels apart)."""
    cells = (np.floor(points / voxel).astype(np.int64) + _HALF) & (2 * _HALF - 1)
    return (cells[:, 0] << 42) | (cells[:, 1] << 21) | cells[:, 2]


def _normals(points: NDArray[np.float64], neighbours: NDArray[np.int64],
             ) -> NDArray[np.float64]:
    """Unit normals: the least-spread direction of each point's neighbours (rows of
    indices into ``points``)."""
    near = points[neighbours]
    centred = near - near.mean(axis=1, keepdims=True)
    _, vectors = np.linalg.eigh(np.matmul(centred.transpose(0, 2, 1), centred))
    normals: NDArray[np.float64] = vectors[:, :, 0]
    return normals


class DenseMap:
    """Refinement target (module docstring): registered scans within ``radius`` of the
    sensor, matched point-to-plane at ``voxel``; queued scans join every ``rebuild``."""

    def __init__(self, voxel: float, radius: float, rebuild: int, threads: int) -> None:
        self.voxel, self.radius, self.rebuild = voxel, radius, rebuild
        self.threads = _threads(threads)
        self.points = np.empty((0, 3))
        self.normals = np.empty((0, 3))
        self.sums = np.empty((0, 3))  # per cell: sum and number of the points in it
        self.counts = np.empty(0)
        self.codes = np.empty(0, np.int64)  # sorted cell codes; ``rows``: their rows
        self.rows = np.empty(0, np.intp)
        self.pending: list[NDArray[np.float64]] = []
        self.tree: _GicpTree | None = None

    def source(self, scan: NDArray[np.float64]) -> NDArray[np.float64]:
        """The scan down-sampled on the map voxel, at most :data:`MAX_SOURCE` points evenly
        spaced."""
        import small_gicp

        grid: GicpCloud = small_gicp.voxelgrid_sampling(scan, self.voxel,
                                                        num_threads=self.threads)
        points = np.asarray(grid.points())[:, :3]
        if len(points) <= MAX_SOURCE:
            return np.ascontiguousarray(points)
        keep = np.linspace(0, len(points) - 1, MAX_SOURCE).astype(np.int64)
        return np.ascontiguousarray(points[keep])

    def add(self, scan: NDArray[np.float64], sensor: NDArray[np.float64], *,
            confirmed: bool = True) -> None:
        """Queue the scan (sensor frame, on a ``voxel / 2`` grid) placed at ``sensor``;
        update the target every ``rebuild`` scans."""
        import small_gicp

        fine: GicpCloud = small_gicp.voxelgrid_sampling(scan, self.voxel / 2,
                                                        num_threads=self.threads)
        pts = np.asarray(fine.points())[:, :3]
        weight = np.full((len(pts), 1), 1.0 if confirmed else 0.0)
        self.pending.append(np.hstack([pts @ sensor[:3, :3].T + sensor[:3, 3], weight]))
        if self.tree is not None and len(self.pending) < self.rebuild:
            return
        first = self._merge(np.vstack(self.pending))
        self.pending = []
        keep = np.linalg.norm(self.sums / self.counts[:, None] - sensor[:3, 3],
                              axis=1) <= self.radius
        first = int(keep[:first].sum())
        self.sums, self.counts = self.sums[keep], self.counts[keep]
        self.normals = self.normals[keep]
        self.points = self.sums / self.counts[:, None]
        codes = _codes(self.points, self.voxel)
        self.rows = np.argsort(codes, kind="stable")
        self.codes = codes[self.rows]
        self._retarget(first)

    def _merge(self, queued: NDArray[np.float64]) -> int:
        """Fold queued points (x, y, z, 1 if confirmed else 0) into the cell sums: all of
        them into new cells (appended), the confirmed ones into held cells. Returns the
        first new row."""
        placed, weight = queued[:, :3], queued[:, 3]
        codes, inverse = np.unique(_codes(placed, self.voxel), return_inverse=True)
        sums = np.stack([np.bincount(inverse, placed[:, k], len(codes)) for k in range(3)],
                        axis=1)
        counts = np.bincount(inverse, minlength=len(codes)).astype(np.float64)
        held = np.zeros(len(codes), bool)
        if len(self.codes):
            where = np.minimum(np.searchsorted(self.codes, codes), len(self.codes) - 1)
            held = self.codes[where] == codes
            rows = self.rows[where[held]]
            self.sums[rows] += np.stack([np.bincount(inverse, placed[:, k] * weight, len(codes))
                                         for k in range(3)], axis=1)[held]
            self.counts[rows] += np.bincount(inverse, weight, len(codes))[held]
        first = len(self.counts)
        self.sums = np.vstack([self.sums, sums[~held]])
        self.counts = np.concatenate([self.counts, counts[~held]])
        self.normals = np.vstack([self.normals, np.zeros((int((~held).sum()), 3))])
        return first

    def _retarget(self, first: int) -> None:
        """k-d tree over the map; normals for points ``first:`` and their neighbours."""
        import small_gicp

        self.tree = small_gicp.KdTree(np.ascontiguousarray(self.points),
                                      num_threads=self.threads)
        k = min(NEIGHBOURS, len(self.points))
        if first >= len(self.points) or k < 3:
            return
        near, _ = self.tree.batch_knn_search(self.points[first:], k, num_threads=self.threads)
        self.normals[first:] = _normals(self.points, np.asarray(near, dtype=np.int64))
        touched = np.asarray(near, dtype=np.int64)[:, :REFRESH].ravel()
        touched = np.unique(touched[touched < first])
        around, _ = self.tree.batch_knn_search(self.points[touched], k, num_threads=self.threads)
        self.normals[touched] = _normals(self.points, np.asarray(around, dtype=np.int64))

    def matches(self, placed: NDArray[np.float64],
                ) -> tuple[NDArray[np.bool_], NDArray[np.int64], NDArray[np.float64]]:
        """For map-frame points: which have a map point within reach, its index (0 where
        none) and the signed point-to-plane residual (m; 0 where none)."""
        assert self.tree is not None  # the first scan builds the target
        found, sq = self.tree.batch_nearest_neighbor_search(placed, num_threads=self.threads)
        index = np.asarray(found, dtype=np.int64)
        inlier = (np.asarray(sq) <= (REACH * self.voxel) ** 2) & (index >= 0) & (
            index < len(self.points))
        index = np.where(inlier, index, 0)
        residual = np.einsum("ij,ij->i", self.normals[index], placed - self.points[index])
        return inlier, index, np.where(inlier, residual, 0.0)

    def cost(self, points: NDArray[np.float64], pose: NDArray[np.float64], cap: float,
             ) -> tuple[float, float]:
        """Inlier fraction and truncated point-to-plane cost (m^2: residuals capped at
        ``cap`` m, points without a match at the cap) of sensor-frame ``points`` placed
        at ``pose``."""
        if not len(points):
            return 0.0, cap * cap
        inlier, _, residual = self.matches(points @ pose[:3, :3].T + pose[:3, 3])
        cost = np.where(inlier, np.minimum(residual ** 2, cap * cap), cap * cap)
        return float(inlier.mean()), float(cost.mean())
