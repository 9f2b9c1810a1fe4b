"""The LiDAR-inertial odometry's local map: world points on a grid near the vehicle, with
the plane fits its point-to-plane update reads (:mod:`alte.registration.lio`).

Each point keeps the position variance of the pose that placed it (VoxelMap's point
uncertainty, Yuan et al. 2022, reduced to the position): a wall mapped while the vehicle's
position along it was uncertain by 0.5 m places the vehicle no better than that when it is
matched again. Taken as exact, three such points collapsed the along-track sigma of
sim_nav_2 from 0.56 to 0.21 m at a turn, onto a copy of the wall the drift itself had made.

Cost: the update asks for the plane fits of one scan three to five times (its iterations)
against the same map, and most scan points keep their neighbours from one iteration to
the next; a fit depends on its neighbours alone, so the map remembers the last fits
(:class:`_Memo`) and fits again only the rows whose neighbours changed. The map's rows
are appended and dropped by a mask under a k-d tree split in two
(:mod:`alte.registration.neighbours`), rather than a tree over the whole map rebuilt
each scan.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TypeVar

import numpy as np
from numpy.typing import NDArray

from alte.registration.neighbours import SplitTree

__all__ = ["LocalMap", "Planes", "voxel_first"]

_T = TypeVar("_T", np.float64, np.int64, np.bool_)


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


def _within(points: NDArray[np.float64], centre: NDArray[np.float64],
            radius: float) -> NDArray[np.bool_]:
    """``norm(points - centre) <= radius`` per point, as :func:`numpy.linalg.norm` decides
    it: a cheap squared distance settles all but the points within 1e-6 of the sphere."""
    offset = points - centre
    square = np.einsum("ij,ij->i", offset, offset)
    near: NDArray[np.bool_] = square < (radius * (1.0 - 1e-6)) ** 2
    edge = np.flatnonzero(~near & (square < (radius * (1.0 + 1e-6)) ** 2))
    near[edge] = np.linalg.norm(offset[edge], axis=1) <= radius
    return near


def _rows(inside: NDArray[np.bool_]) -> NDArray[np.bool_]:
    """The rows of a neighbour mask that are all inside."""
    return np.asarray(inside.all(axis=1), dtype=np.bool_)


def _distance(points: NDArray[np.float64], centre: NDArray[np.float64]) -> NDArray[np.float64]:
    """Each point's distance to ``centre`` (to within rounding: a bound, not a decision)."""
    offset = points - centre
    out: NDArray[np.float64] = np.sqrt(np.einsum("ij,ij->i", offset, offset))
    return out


def _put(array: NDArray[_T], rows: int, new: NDArray[_T]) -> NDArray[_T]:
    """``new`` written after the first ``rows`` rows of ``array``, grown (doubled) when full:
    appending a scan's few hundred rows costs them, not the map."""
    need = rows + len(new)
    if need > len(array):
        grown = np.empty((max(need, 2 * len(array)), *array.shape[1:]), array.dtype)
        grown[:rows] = array[:rows]
        array = grown
    array[rows:need] = new
    return array


@dataclass(frozen=True)
class Planes:
    """The plane fits of the query points that got one: their ``index`` among the queries,
    the unit ``normal``, a point of the plane (``centre``) and the ``variance`` (m^2)
    along the normal of where the map point nearest the query was placed."""

    index: NDArray[np.intp]
    normal: NDArray[np.float64]
    centre: NDArray[np.float64]
    variance: NDArray[np.float64]


@dataclass
class _Memo:
    """The last fits of one neighbour count against the current map: per query row its
    neighbour indices, whether it was fitted, and the fit (flat, normal, centre)."""

    idx: NDArray[np.int64]
    done: NDArray[np.bool_]
    flat: NDArray[np.bool_]
    normal: NDArray[np.float64]
    centre: NDArray[np.float64]

    def reusable(self, idx: NDArray[np.int64]) -> NDArray[np.bool_]:
        """The rows of ``idx`` fitted last time with the same neighbours, in order."""
        if self.idx.shape != idx.shape:
            return np.zeros(len(idx), dtype=np.bool_)
        same: NDArray[np.bool_] = self.done & (self.idx == idx).all(axis=1)
        return same


class LocalMap:
    """World points near the vehicle on a grid, with k-d trees for plane fits. Rows are
    appended (into arrays grown by doubling) and dropped by a mask
    (:class:`~alte.registration.neighbours.SplitTree`), and packed when the rows added or
    dropped since the last packing pass ``repack`` of it. Each row keeps its distance to
    an anchor, so that only the rows that may have left ``radius`` since are measured."""

    def __init__(self, voxel: float, radius: float, thickness: float = 0.05,
                 repack: float = 0.1) -> None:
        self.voxel, self.radius, self.thickness, self.repack = voxel, radius, thickness, repack
        self.rows = 0
        self._points, self._variance = np.empty((0, 3)), np.empty((0, 3))
        self._live, self._cells = np.empty(0, np.bool_), np.empty(0, np.int64)
        self._reach, self._anchor = np.empty(0), np.zeros(3)
        self.keys = np.empty(0, np.int64)  # the live rows' cell keys, sorted
        self.index = SplitTree(self.points, self.live)
        self._memo: dict[int, _Memo] = {}

    @property
    def points(self) -> NDArray[np.float64]:
        """Every row's world point (live or dropped)."""
        return self._points[:self.rows]

    @property
    def variance(self) -> NDArray[np.float64]:
        """Every row's position variance (x, y, z; m^2) of the pose that placed it."""
        return self._variance[:self.rows]

    @property
    def live(self) -> NDArray[np.bool_]:
        """Whether each row is still in the map."""
        return self._live[:self.rows]

    @property
    def ready(self) -> bool:
        """Whether the map holds enough points (five) to fit planes."""
        return len(self.keys) >= 5

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
        self._append(new[fresh], keys[fresh], placed)
        self._drop(centre)
        if 2 * self.rows - len(self.keys) - self.index.base > self.repack * self.index.base:
            self._pack()
        else:
            self.index.update(self.points, self.live)

    def _append(self, new: NDArray[np.float64], keys: NDArray[np.int64],
                placed: NDArray[np.float64]) -> None:
        """Rows for the ``new`` points of cell ``keys``, placed with variance ``placed``."""
        n = self.rows
        self._points = _put(self._points, n, new)
        self._variance = _put(self._variance, n, np.tile(placed, (len(new), 1)))
        self._cells = _put(self._cells, n, keys)
        self._live = _put(self._live, n, np.ones(len(new), np.bool_))
        self._reach = _put(self._reach, n, _distance(new, self._anchor))
        self.rows = n + len(new)
        sort = np.sort(keys)
        self.keys = np.insert(self.keys, np.searchsorted(self.keys, sort), sort)

    def _drop(self, centre: NDArray[np.float64]) -> None:
        """Rows beyond ``radius`` of ``centre`` out of the map; measured are only those
        whose distance to the anchor, plus how far ``centre`` moved from it, may exceed
        it (the anchor moves to ``centre`` when that is 2 % of the radius)."""
        moved = float(np.linalg.norm(centre - self._anchor))
        if moved > 0.02 * self.radius:
            self._anchor, moved = np.array(centre, dtype=np.float64), 0.0
            self._reach[:self.rows] = _distance(self.points, self._anchor)
        maybe = np.flatnonzero(self.live & (self._reach[:self.rows]
                                            > self.radius * (1.0 - 1e-6) - moved))
        dead = maybe[~_within(self.points[maybe], centre, self.radius)]
        if len(dead):
            self._live[dead] = False
            self.keys = np.delete(self.keys, np.searchsorted(self.keys, self._cells[dead]))

    def _pack(self) -> None:
        """Only the live rows kept, sorted by cell (neighbours close in memory too), under
        a new k-d tree (row numbers change)."""
        keep = np.flatnonzero(self.live)
        keep = keep[np.argsort(self._cells[keep])]
        self._points, self._variance = self._points[keep], self._variance[keep]
        self._cells, self._live = self._cells[keep], self._live[keep]
        self._reach, self.rows = self._reach[keep], len(keep)
        self.index = SplitTree(self.points, self.live)
        self._memo.clear()

    def planes(self, query: NDArray[np.float64], max_distance: float, k: int = 5,
               wide: tuple[int, float] = (0, 0.0)) -> Planes:
        """For each query point whose ``wide = (points, reach)`` map neighbours lie on a
        plane (thinner than ``thickness``, and not a line as a ring's points are), or
        else its ``k`` nearest within ``max_distance``: :class:`Planes`. A normal fitted to
        twenty points over metres tilts far less than one fitted to five, and a tilted
        normal reads as a constraint along the ground; the five keep small objects and
        edges."""
        if not self.ready or len(query) == 0:
            return Planes(np.empty(0, np.intp), np.empty((0, 3)), np.empty((0, 3)),
                          np.empty(0))
        count = max(k, wide[0])
        dist, idx = self.index.query(query, count, max(max_distance, wide[1]))
        small = _rows(dist[:, :k] <= max_distance)
        if wide[0] > k:  # the small fit only where the wide one fails
            flat, normal, centre = self._fit(idx, _rows(dist <= wide[1]))
            few, few_normal, few_centre = self._fit(idx[:, :k], small & ~flat)
            normal[~flat], centre[~flat] = few_normal[~flat], few_centre[~flat]
            flat |= few
        else:
            flat, normal, centre = self._fit(idx[:, :k], small)
        index = np.flatnonzero(flat)
        placed = self.variance[idx[index, 0]]
        return Planes(index, normal[index], centre[index],
                      np.einsum("ij,ij->i", normal[index] ** 2, placed))

    def _fit(self, idx: NDArray[np.int64], ok: NDArray[np.bool_],
             ) -> tuple[NDArray[np.bool_], NDArray[np.float64], NDArray[np.float64]]:
        """For the ``ok`` rows of neighbour indices: whether they lie on a plane, its unit
        normal and the neighbours' centroid; rows fitted last time against this map with
        the same neighbours are taken from :class:`_Memo`."""
        memo = self._memo.get(idx.shape[1])
        reuse = ok & memo.reusable(idx) if memo is not None \
            else np.zeros(len(idx), dtype=np.bool_)
        flat, normal, centre = np.zeros(len(idx), np.bool_), np.zeros((len(idx), 3)), \
            np.zeros((len(idx), 3))
        if memo is not None and reuse.any():
            flat[reuse], normal[reuse], centre[reuse] = memo.flat[reuse], \
                memo.normal[reuse], memo.centre[reuse]
        todo = ok & ~reuse
        flat[todo], normal[todo], centre[todo] = self._plane(idx[todo])
        self._memo[idx.shape[1]] = _Memo(idx, ok.copy(), flat.copy(), normal.copy(),
                                         centre.copy())
        return flat, normal, centre

    def _plane(self, idx: NDArray[np.int64],
               ) -> tuple[NDArray[np.bool_], NDArray[np.float64], NDArray[np.float64]]:
        """Per row of neighbour indices: whether they lie on a plane, its unit normal and
        their centroid (each row on its own: the same neighbours give the same fit)."""
        from alte.registration.lio_kernels import plane_fits  # numba: on first use

        return plane_fits(self.points, np.ascontiguousarray(idx), self.thickness)
