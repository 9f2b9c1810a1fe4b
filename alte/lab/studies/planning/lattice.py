"""A uniform planning lattice classified by a 3D map: occupied, free or unknown nodes.

The planner does not walk the map's own leaves (3D-ALTE's variable-size cubes,
Octomap's pruned voxels): it samples the domain with a lattice of spacing ``step``
and asks the map what each node lies in. A node is *blocked* when an occupied cell
comes within ``clearance + step * sqrt(3) / 2`` of it: the extra half-diagonal
guarantees that every point of a straight edge between two unblocked 26-neighbours
keeps ``clearance`` from every occupied cell of the map.

Free versus unknown space (thesis 3.2, 5.1): Octomap marks the voxels its rays
cross as free, so "unknown" is what no ray reached; 3D-ALTE only tells occupied from
*unoccupied* cells, and unoccupied is not observed free, so every node outside an
occupied cell is unknown. The ``unknown`` policy decides what unknown nodes are:
``"free"`` (optimistic) or ``"occupied"`` (conservative: a node is then also blocked
when an unknown node lies within the same inflated radius, measured on the lattice).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.ndimage import distance_transform_edt
from scipy.spatial import cKDTree

from alte.errors import MapperError, ParameterError
from alte.mappers.base import Cells, Mapper

__all__ = ["FREE", "MAX_NODES", "OCCUPIED", "POLICIES", "UNKNOWN",
           "Lattice", "PlanningMap", "blocked_nodes", "classify", "locate", "near_boxes",
           "planning_map"]

#: Node states.
UNKNOWN, FREE, OCCUPIED = 0, 1, 2
#: What unknown space is taken to be.
POLICIES: tuple[str, ...] = ("free", "occupied")
#: Largest lattice the planner builds (memory: about 100 bytes per node with edges).
MAX_NODES = 3_000_000


@dataclass(frozen=True)
class Lattice:
    """Nodes ``origin + step * (i, j, k)`` for ``(i, j, k) < shape`` (C order)."""

    origin: NDArray[np.float64]
    step: float
    shape: tuple[int, int, int]

    @classmethod
    def over(cls, bounds: object, step: float) -> Lattice:
        """The lattice from the min corner of ``bounds`` (2, 3) to within a step of the max."""
        box = np.asarray(bounds, dtype=np.float64)
        if box.shape != (2, 3) or not np.isfinite(box).all() or (box[1] <= box[0]).any():
            raise ParameterError(f"planning bounds must be (2, 3) min/max corners with max > min, "
                                 f"got {box.tolist()}")
        if not (np.isfinite(step) and step > 0):
            raise ParameterError(f"planning step={step!r} must be a positive number (m)")
        nx, ny, nz = (int(n) for n in np.floor((box[1] - box[0]) / step + 1e-9).astype(int) + 1)
        shape = (nx, ny, nz)
        if int(np.prod(shape)) > MAX_NODES:
            raise ParameterError(f"planning step={step} m gives {int(np.prod(shape))} lattice "
                                 f"nodes over {box.tolist()} (limit {MAX_NODES}); use a larger "
                                 "step or smaller bounds")
        return cls(box[0].copy(), float(step), shape)

    @property
    def size(self) -> int:
        return int(np.prod(self.shape))

    @property
    def upper(self) -> NDArray[np.float64]:
        """The last node (max corner of the lattice)."""
        return self.origin + self.step * (np.array(self.shape) - 1)

    def points(self) -> NDArray[np.float64]:
        """Coordinates of every node (N, 3), in node-index order."""
        axes = [self.origin[a] + self.step * np.arange(n) for a, n in enumerate(self.shape)]
        grid = np.meshgrid(*axes, indexing="ij")
        return np.stack([g.reshape(-1) for g in grid], axis=1)

    def node_points(self, indices: NDArray[np.intp]) -> NDArray[np.float64]:
        """Coordinates of the nodes with flat ``indices`` (M, 3)."""
        ijk = np.stack(np.unravel_index(np.asarray(indices, dtype=np.int64), self.shape), axis=1)
        points: NDArray[np.float64] = self.origin + self.step * ijk
        return points

    def nearest(self, point: object, name: str = "point") -> int:
        """Index of the node nearest to ``point``; raises when it lies outside the lattice."""
        p = np.asarray(point, dtype=np.float64).reshape(-1)
        if p.shape != (3,) or not np.isfinite(p).all():
            raise ParameterError(f"planning {name} must be 3 finite numbers, got {p.tolist()}")
        tol = self.step / 2
        if ((p < self.origin - tol) | (p > self.upper + tol)).any():
            raise ParameterError(f"planning {name} {p.tolist()} lies outside the lattice "
                                 f"{self.origin.tolist()} .. {self.upper.tolist()}")
        ijk = np.clip(np.rint((p - self.origin) / self.step), 0, np.array(self.shape) - 1)
        return int(np.ravel_multi_index(ijk.astype(np.int64), self.shape))


@dataclass(frozen=True, eq=False)
class PlanningMap:
    """A 3D map's leaves and which of them are occupied / observed free."""

    name: str
    cells: Cells
    free: NDArray[np.bool_]

    @classmethod
    def from_cells(cls, cells: Cells, observes_free: bool, name: str = "map") -> PlanningMap:
        """Wrap ``cells``; with ``observes_free`` the unoccupied leaves are free space."""
        if cells.centers.ndim != 2 or cells.centers.shape[1] != 3:
            raise MapperError(f"{name}: cell centres must be (K, 3), got {cells.centers.shape}")
        occupied = np.asarray(cells.occupied, dtype=bool)
        known = np.isfinite(cells.centers).all(axis=1) & (cells.sizes > 0).all(axis=1)
        if not known.all():
            raise MapperError(f"{name}: {int((~known).sum())} cells have no 3D extent; "
                              "path planning needs a volumetric (3D) map")
        free = ~occupied if observes_free else np.zeros_like(occupied)
        return cls(name, cells, free)

    @property
    def occupied(self) -> NDArray[np.bool_]:
        return np.asarray(self.cells.occupied, dtype=bool)


def planning_map(mapper: Mapper) -> PlanningMap:
    """The planning view of a 3D mapper (Octomap: free leaves; 3D-ALTE: none)."""
    if mapper.dims != 3:
        raise MapperError(f"{mapper.name}: path planning needs a 3D map, got a "
                          f"{mapper.dims}D height map")
    return PlanningMap.from_cells(mapper.cells(), mapper.free_space, mapper.name)


def _level_groups(cells: Cells, name: str) -> list[tuple[NDArray[np.intp], NDArray[np.float64]]]:
    """Cell indices and their common size, per tree level (one size per level)."""
    groups = []
    for level in np.unique(cells.level):
        members = np.flatnonzero(cells.level == level)
        sizes = cells.sizes[members]
        if np.ptp(sizes, axis=0).max() > 1e-9 * max(1.0, float(sizes.max())):
            raise MapperError(f"{name}: cells of level {int(level)} differ in size")
        groups.append((members, sizes[0]))
    return groups


def locate(cells: Cells, points: NDArray[np.float64], name: str = "map") -> NDArray[np.int64]:
    """Index of the cell containing each point (-1 where none), one hash lookup per level."""
    out = np.full(len(points), -1, dtype=np.int64)
    for members, size in _level_groups(cells, name):
        lo = cells.centers[members] - size / 2
        anchor = lo.min(axis=0)
        keys = np.rint((lo - anchor) / size).astype(np.int64)
        span = keys.max(axis=0) + 1
        ijk = np.floor((points - anchor) / size).astype(np.int64)
        inside = np.flatnonzero(((ijk >= 0) & (ijk < span)).all(axis=1))
        table = np.ravel_multi_index(keys.T, span)
        order = np.argsort(table)
        table = table[order]
        query = np.ravel_multi_index(ijk[inside].T, span)
        pos = np.minimum(np.searchsorted(table, query), table.size - 1)
        hit = table[pos] == query
        out[inside[hit]] = members[order[pos[hit]]]
    return out


def classify(lattice_points: NDArray[np.float64], pmap: PlanningMap) -> NDArray[np.uint8]:
    """State of every point: :data:`OCCUPIED`, :data:`FREE` or :data:`UNKNOWN` (uint8)."""
    idx = locate(pmap.cells, lattice_points, pmap.name)
    states = np.full(len(lattice_points), UNKNOWN, dtype=np.uint8)
    found = idx >= 0
    states[found] = np.where(pmap.occupied[idx[found]], OCCUPIED,
                             np.where(pmap.free[idx[found]], FREE, UNKNOWN))
    return states


def near_boxes(points: NDArray[np.float64], centers: NDArray[np.float64],
               sizes: NDArray[np.float64], level: NDArray[np.int64],
               radius: float) -> NDArray[np.bool_]:
    """True where a point lies within ``radius`` of an axis-aligned box (exact distance).

    Per box size, a KD-tree on box centres settles most points (centre distance is an
    upper bound, centre distance minus half-diagonal a lower bound); only points in the
    band between are checked against each nearby box exactly.
    """
    hit = np.zeros(len(points), dtype=bool)
    if len(centers) == 0 or len(points) == 0:
        return hit
    cells = Cells(centers, sizes, np.zeros(len(centers)), np.ones(len(centers), bool), level)
    for members, size in _level_groups(cells, "occupied cells"):
        half = size / 2
        reach = radius + float(np.linalg.norm(half))
        tree = cKDTree(centers[members])
        dist, _ = tree.query(points, k=1, distance_upper_bound=reach)
        hit |= dist <= radius
        band = np.flatnonzero(~hit & (dist <= reach))
        if band.size == 0:
            continue
        pairs = cKDTree(points[band]).sparse_distance_matrix(tree, reach, output_type="ndarray")
        near: NDArray[np.intp] = band[pairs["i"]]
        offset: NDArray[np.float64] = points[near] - centers[members[pairs["j"]]]
        gap = np.maximum(np.abs(offset) - half, 0.0)
        hit[near[np.linalg.norm(gap, axis=1) <= radius]] = True
    return hit


def blocked_nodes(lattice: Lattice, pmap: PlanningMap, clearance: float,
                  unknown: str = "free") -> tuple[NDArray[np.bool_], NDArray[np.uint8]]:
    """(blocked mask, node states) of the lattice for a clearance radius and unknown policy."""
    if not (np.isfinite(clearance) and clearance >= 0):
        raise ParameterError(f"planning clearance={clearance!r} must be >= 0 (m)")
    if unknown not in POLICIES:
        raise ParameterError(f"planning unknown={unknown!r}: expected one of {POLICIES}")
    pts = lattice.points()
    states = classify(pts, pmap)
    radius = clearance + lattice.step * np.sqrt(3) / 2
    occ = pmap.occupied
    blocked = (states == OCCUPIED) | near_boxes(pts, pmap.cells.centers[occ],
                                                pmap.cells.sizes[occ], pmap.cells.level[occ],
                                                radius)
    unknown_grid = (states == UNKNOWN).reshape(lattice.shape)
    if unknown == "occupied" and unknown_grid.any():
        to_unknown = distance_transform_edt(~unknown_grid, sampling=lattice.step)
        blocked |= to_unknown.reshape(-1) <= radius
    return blocked, states
