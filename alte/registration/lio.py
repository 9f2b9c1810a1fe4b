"""LiDAR-inertial odometry: scans registered point-to-plane inside an IMU error-state filter.

The IMU (:mod:`alte.registration.inertial`) carries the state from scan to scan and through
each sweep; every scan is then

1. deskewed to its stamp with the IMU's motion over the sweep (each point moved from its
   own instant, the per-point time, with the mean rate and acceleration of the sweep);
2. down-sampled on ``voxel`` and registered point-to-plane against a local map of the
   scans before it, as the measurement of an iterated Kalman update (FAST-LIO's scheme:
   correspondences found again at every iteration). Planes are fitted to the
   ``wide_points`` nearest map points within ``wide_reach`` where they are flat, else to
   the ``neighbours`` nearest within ``max_distance`` (five, FAST-LIO's choice): a ground
   point's five nearest lie along one scan ring (a line, refused), twenty span rings.
   Directions of the pose a scan informs less than ``least`` keep the IMU's prediction
   (:func:`~alte.registration.inertial.strong_directions`): over flat ground x, y and yaw
   get only the false information of normals tilted by noise, which the filter would
   fold into velocity and accelerometer bias; LiDAR-only odometry slides there;
3. added to the map (``voxel / 2`` grid, points beyond ``max_range`` of the vehicle dropped).

The world frame is the first scan's body pose (the recorded one when the bag has poses,
else level from the accelerometer), gravity along -z. Two PyPI packages were tried first
(environment.md); both diverged on the simulated UAV missions.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray
from scipy.spatial import cKDTree
from scipy.spatial.transform import Rotation

from alte.errors import RegistrationError
from alte.registration.inertial import ImuNoise, InertialFilter, NavState, Residuals
from alte.types import Frame, Mount

if TYPE_CHECKING:
    from alte.io.imu import ImuSamples

__all__ = ["LioOdometry", "LioSettings", "LocalMap", "check_overlap", "lio_frames"]


@dataclass(frozen=True)
class LioSettings:
    """What the LIO reads from :class:`~alte.registration.odometry.OdometryParams`
    (``iterations`` and ``noise`` are not settings of ``--odometry-set``)."""

    voxel: float = 0.5
    max_range: float = 100.0
    min_range: float = 1.0
    plane_sigma: float = 0.15
    max_distance: float = 2.0
    neighbours: int = 5
    wide_points: int = 20
    wide_reach: float = 3.0
    least: float = 30.0
    iterations: int = 5
    noise: ImuNoise = field(default_factory=ImuNoise)


def _matrix(position: NDArray[np.float64], rotation: Rotation[tuple[()]]) -> NDArray[np.float64]:
    out = np.eye(4)
    out[:3, :3], out[:3, 3] = rotation.as_matrix(), position
    return out


def _cells(points: NDArray[np.float64], voxel: float) -> NDArray[np.int64]:
    """One int64 key per ``voxel`` cell (21 bits an axis: +-500 km at 0.25 m)."""
    index = np.floor(points / voxel).astype(np.int64) + (1 << 20)
    keys: NDArray[np.int64] = (index[:, 0] << 42) | (index[:, 1] << 21) | index[:, 2]
    return keys


def _voxel_first(points: NDArray[np.float64], voxel: float) -> NDArray[np.float64]:
    """One point per ``voxel`` cell (the first): a cheap, deterministic down-sampling."""
    if len(points) == 0:
        return points
    _, first = np.unique(_cells(points, voxel), return_index=True)
    return points[np.sort(first)]


class LocalMap:
    """World points near the vehicle on a grid, with a k-d tree for plane fits."""

    def __init__(self, voxel: float, radius: float, thickness: float = 0.05) -> None:
        self.voxel, self.radius, self.thickness = voxel, radius, thickness
        self.points = np.empty((0, 3))
        self.keys = np.empty(0, np.int64)
        self.tree: cKDTree | None = None

    def add(self, points: NDArray[np.float64], centre: NDArray[np.float64]) -> None:
        """Add ``points`` (world) in cells not yet filled; drop what lies beyond ``radius``
        of ``centre``."""
        new = _voxel_first(points, self.voxel)
        keys = _cells(new, self.voxel)
        at = np.clip(np.searchsorted(self.keys, keys), 0, max(len(self.keys) - 1, 0))
        fresh = ~(self.keys[at] == keys) if len(self.keys) else np.ones(len(keys), bool)
        merged = np.vstack([self.points, new[fresh]])
        cells = np.r_[self.keys, keys[fresh]]
        near = np.linalg.norm(merged - centre, axis=1) <= self.radius
        order = np.argsort(cells[near], kind="stable")
        self.points, self.keys = merged[near][order], cells[near][order]
        self.tree = cKDTree(self.points, balanced_tree=False, compact_nodes=False) \
            if len(self.points) >= 5 else None

    def planes(self, query: NDArray[np.float64], max_distance: float, k: int = 5,
               wide: tuple[int, float] = (0, 0.0),
               ) -> tuple[NDArray[np.intp], NDArray[np.float64], NDArray[np.float64]]:
        """For each query point whose ``wide = (points, reach)`` map neighbours lie on a
        plane (thinner than ``thickness``, and not a line as a ring's points are), or
        else its ``k`` nearest within ``max_distance``: its index, the plane's unit normal
        and a point of the plane. A normal fitted to twenty points over metres tilts far
        less than one fitted to five, and a tilted normal reads as a constraint along the
        ground; the five keep small objects and edges."""
        if self.tree is None or len(query) == 0:
            return np.empty(0, np.int64), np.empty((0, 3)), np.empty((0, 3))
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
        return index, normal[index], centre[index]

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


def check_overlap(imu: ImuSamples, stamp: int) -> None:
    """Raise when the IMU does not cover a scan stamp (another clock or unit)."""
    lo, hi = int(imu.stamps[0]), int(imu.stamps[-1])
    if not lo - 1_000_000_000 <= stamp <= hi + 1_000_000_000:
        raise RegistrationError(
            f"--odometry lio: scan stamp {stamp} ns lies outside the IMU topic's "
            f"{lo}..{hi} ns (another clock or unit?); use --odometry kiss")


class LioOdometry:
    """The filter, the map and the LiDAR's pose on the IMU (module docstring)."""

    def __init__(self, imu: ImuSamples, lidar: Mount, settings: LioSettings,
                 start: tuple[NDArray[np.float64], NDArray[np.float64]] | None, first: int) -> None:
        self.imu, self.settings = imu, settings
        imu_mount = imu.mount or Mount()
        self.body_imu = _matrix(imu_mount.translation, imu_mount.rotation)
        self.imu_lidar = np.linalg.inv(self.body_imu) @ _matrix(lidar.translation,
                                                                lidar.rotation)
        body = self._level(first) if start is None \
            else _matrix(start[0], Rotation.from_quat(start[1]))
        world_imu = body @ self.body_imu
        state = NavState(first, Rotation.from_matrix(world_imu[:3, :3]), world_imu[:3, 3],
                         np.zeros(3), np.zeros(3), np.zeros(3))
        self.filter = InertialFilter(state, settings.noise)
        self.map = LocalMap(settings.voxel / 2, settings.max_range)

    def _level(self, stamp: int) -> NDArray[np.float64]:
        """A body pose at the origin, level by the mean specific force of the first 0.1 s."""
        near = np.abs(self.imu.stamps - stamp) <= 50_000_000
        force = self.imu.linear_acceleration[near].mean(axis=0) if near.any() \
            else self.imu.linear_acceleration[0]
        up = self.body_imu[:3, :3] @ force
        tilt, _ = Rotation.align_vectors([[0.0, 0.0, 1.0]], [up])
        return _matrix(np.zeros(3), tilt)

    def _window(self, start: int, end: int) -> slice[int, int]:
        """Samples that can cover ``[start, end]`` (one either side)."""
        lo = max(int(np.searchsorted(self.imu.stamps, start)) - 1, 0)
        hi = int(np.searchsorted(self.imu.stamps, end)) + 1
        return slice(lo, hi)

    def deskew(self, points: NDArray[np.float64], times: NDArray[np.float64] | None,
               ) -> NDArray[np.float64]:
        """Scan points (LiDAR frame) in the IMU frame at the stamp, moved with the sweep's
        mean rate and acceleration from each point's instant (``times``, s)."""
        state = self.filter.state
        lidar = points @ self.imu_lidar[:3, :3].T + self.imu_lidar[:3, 3]
        if times is None or len(times) == 0 or np.ptp(times) <= 0:
            return np.asarray(lidar)
        span = self._window(state.stamp, state.stamp + int(float(np.max(times)) * 1e9))
        gyro = self.imu.angular_velocity[span].mean(axis=0) - state.gyro_bias
        force = self.imu.linear_acceleration[span].mean(axis=0) - state.accel_bias
        accel = state.rotation.apply(force) + np.array([0.0, 0.0, -9.81])
        tau = np.asarray(times, dtype=np.float64)[:, None]
        rot = Rotation.from_rotvec(tau * gyro)
        shift = state.rotation.inv().apply(state.velocity * tau + 0.5 * accel * tau**2)
        moved: NDArray[np.float64] = rot.apply(lidar) + shift
        return moved

    def _residuals(self, scan: NDArray[np.float64],
                   ) -> Callable[[NavState], Residuals]:
        settings = self.settings

        def residuals(state: NavState) -> Residuals:
            rot = state.rotation.as_matrix()
            world = scan @ rot.T + state.position
            index, normal, centre = self.map.planes(
                world, settings.max_distance, settings.neighbours,
                (settings.wide_points, settings.wide_reach))
            r = np.einsum("ij,ij->i", normal, world[index] - centre)
            keep = np.abs(r) < settings.max_distance / 2
            index, normal, r = index[keep], normal[keep], r[keep]
            # d r / d theta = -n^T R [q]x ; d r / d p = n^T
            nr = normal @ rot
            jac = np.hstack([np.cross(scan[index], nr), normal])
            return r, jac

        return residuals

    def step(self, frame: Frame) -> NDArray[np.float64]:
        """The body pose (4x4, world) at the frame's stamp."""
        check_overlap(self.imu, frame.stamp)
        span = self._window(self.filter.state.stamp, frame.stamp)
        self.filter.predict(frame.stamp, self.imu.stamps[span],
                            self.imu.angular_velocity[span], self.imu.linear_acceleration[span])
        points = np.asarray(frame.points, dtype=np.float64)
        ranges = np.linalg.norm(points, axis=1)
        keep = np.isfinite(ranges) & (ranges >= self.settings.min_range) \
            & (ranges <= self.settings.max_range)
        times = None if frame.times is None else np.asarray(frame.times)[keep]
        scan = self.deskew(points[keep], times)
        if self.map.tree is not None:
            self.filter.update(self._residuals(_voxel_first(scan, self.settings.voxel)),
                               self.settings.plane_sigma, self.settings.iterations,
                               least=self.settings.least)
        state = self.filter.state
        self.map.add(scan @ state.rotation.as_matrix().T + state.position, state.position)
        return state.matrix() @ np.linalg.inv(self.body_imu)


def lio_frames(frames: Iterable[Frame], lidar: Mount, imu: ImuSamples, settings: LioSettings,
               start: tuple[NDArray[np.float64], NDArray[np.float64]] | None = None) -> Iterator[
                   tuple[Frame, NDArray[np.float64]]]:
    """Each frame with its body pose (4x4) from LIO, anchored at ``start``."""
    odometry: LioOdometry | None = None
    for frame in frames:
        if odometry is None:
            check_overlap(imu, frame.stamp)
            odometry = LioOdometry(imu, lidar, settings, start, frame.stamp)
        yield frame, odometry.step(frame)
