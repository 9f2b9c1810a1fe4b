"""The LiDAR-inertial odometry's local map: world points on a grid near the vehicle, with
the plane fits its point-to-plane update reads (:mod:`alte.registration.lio`).

Each point keeps the position variance of the pose that placed it (VoxelMap's point
uncertainty, Yuan et al. 2022, reduced to the position): a wall mapped while the vehicle's
position along it was uncertain by 0.5 m places the vehicle no better than that when it is
matched again. Taken as exact, three such points collapsed the along-track sigma of
sim_nav_2 from 0.56 to 0.21 m at a turn, onto a copy of the wall the drift itself had made.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.spatial import cKDTree

__all__ = ["LocalMap", "Planes", "voxel_first"]


def _cells(points: NDArray[np.float64], voxel: float) -> NDArray[np.int64]:
    """One int64 key per ``voxel`` cell (21 bits an axis: +-500 km at 0.25 m)."""
    index = np.floor(points / voxel).astype(np.int64) + (1 << 20)
    keys: NDArray[np.int64] = (index[:, 0] << 42) | (index[:, 1] << 21) | index[:, 2]
    return keys


def voxel_first(points: NDArray[np.float64], voxel: float) -> NDArray[np.float64]:
    """One point per ``voxel`` cell (the first): a cheap, deterministic down-sampling."""
    if len(points) == 0:
        return points
    _, first = np.unique(_cells(points, voxel), return_index=True)
    return points[np.sort(first)]


@dataclass(frozen=True)
class Planes:
    """The plane fits of the query points that got one: their ``index`` among the queries,
    the unit ``normal``, a point of the plane (``centre``) and the ``variance`` (m^2)
    along the normal of where the map point nearest the query was placed."""

    index: NDArray[np.intp]
    normal: NDArray[np.float64]
    centre: NDArray[np.float64]
    variance: NDArray[np.float64]


class LocalMap:
    """World points near the vehicle on a grid, with a k-d tree for plane fits."""

    def __init__(self, voxel: float, radius: float, thickness: float = 0.05) -> None:
        self.voxel, self.radius, self.thickness = voxel, radius, thickness
        self.points = np.empty((0, 3))
        self.keys = np.empty(0, np.int64)
        self.variance = np.empty((0, 3))
        self.tree: cKDTree | None = None

    def add(self, points: NDArray[np.float64], centre: NDArray[np.float64],
            variance: NDArray[np.float64] | None = None) -> None:
        """Add ``points`` (world) in cells not yet filled, with the position ``variance``
        (x, y, z; m^2; None: exact) of the pose that placed them; drop what lies beyond
        ``radius`` of ``centre``."""
        new = voxel_first(points, self.voxel)
        keys = _cells(new, self.voxel)
        at = np.clip(np.searchsorted(self.keys, keys), 0, max(len(self.keys) - 1, 0))
        fresh = ~(self.keys[at] == keys) if len(self.keys) else np.ones(len(keys), bool)
        placed = np.zeros(3) if variance is None else np.asarray(variance, dtype=np.float64)
        merged = np.vstack([self.points, new[fresh]])
        spread = np.vstack([self.variance, np.tile(placed, (int(fresh.sum()), 1))])
        cells = np.r_[self.keys, keys[fresh]]
        near = np.linalg.norm(merged - centre, axis=1) <= self.radius
        order = np.argsort(cells[near], kind="stable")
        self.points, self.keys = merged[near][order], cells[near][order]
        self.variance = spread[near][order]
        self.tree = cKDTree(self.points, balanced_tree=False, compact_nodes=False) \
            if len(self.points) >= 5 else None

    def planes(self, query: NDArray[np.float64], max_distance: float, k: int = 5,
               wide: tuple[int, float] = (0, 0.0)) -> Planes:
        """For each query point whose ``wide = (points, reach)`` map neighbours lie on a
        plane (thinner than ``thickness``, and not a line as a ring's points are), or
        else its ``k`` nearest within ``max_distance``: :class:`Planes`. A normal fitted to
        twenty points over metres tilts far less than one fitted to five, and a tilted
        normal reads as a constraint along the ground; the five keep small objects and
        edges."""
        if self.tree is None or len(query) == 0:
            return Planes(np.empty(0, np.intp), np.empty((0, 3)), np.empty((0, 3)),
                          np.empty(0))
        count = max(k, wide[0])
        dist, found = self.tree.query(query, k=count,
                                      distance_upper_bound=max(max_distance, wide[1]))
        dist = np.asarray(dist).reshape(-1, count)
        idx = np.asarray(found, dtype=np.int64).reshape(-1, count)
        flat, normal, centre = self._fit(idx[:, :k], dist[:, :k] <= max_distance)
        if wide[0] > k:
            broad, wide_normal, wide_centre = self._fit(idx, dist <= wide[1])
            normal[broad], centre[broad] = wide_normal[broad], wide_centre[broad]
            flat |= broad
        index = np.flatnonzero(flat)
        placed = self.variance[idx[index, 0]]
        return Planes(index, normal[index], centre[index],
                      np.einsum("ij,ij->i", normal[index] ** 2, placed))

    def _fit(self, idx: NDArray[np.int64], inside: NDArray[np.bool_],
             ) -> tuple[NDArray[np.bool_], NDArray[np.float64], NDArray[np.float64]]:
        """Per row of neighbour indices: whether all are ``inside`` and on a plane, the
        plane's unit normal and the neighbours' centroid."""
        ok: NDArray[np.bool_] = np.asarray(inside.all(axis=1), dtype=np.bool_)
        normal, centre = np.zeros((len(idx), 3)), np.zeros((len(idx), 3))
        nbrs = self.points[idx[ok]]
        centre[ok] = nbrs.mean(axis=1)
        centred = nbrs - centre[ok][:, None, :]
        values, vectors = np.linalg.eigh(np.einsum("nki,nkj->nij", centred, centred)
                                         / idx.shape[1])
        spread = np.sqrt(np.maximum(values, 0.0))
        good = (spread[:, 0] < self.thickness) & (spread[:, 1] > 3.0 * self.thickness)
        normal[ok] = vectors[:, :, 0]
        flat = ok.copy()
        flat[ok] = good
        return flat, normal, centre
