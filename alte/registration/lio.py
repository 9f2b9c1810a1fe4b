"""LiDAR-inertial odometry: scans registered point-to-plane inside an IMU error-state filter.

The IMU (:mod:`alte.registration.inertial`) carries the state from scan to scan and through
each sweep. It starts at rest when the IMU log holds at least 0.5 s of stillness in the 2 s
before the first scan (a flight log begun before departure): velocity zero, gyroscope bias
the mean rate, accelerometer bias the mean force less gravity in the start attitude, turned
back to the rest by the gyroscope (:meth:`~alte.registration.inertial.InertialFilter.settle`).
Without it the accelerometer's turn-on bias (0.2 m/s^2 on a MEMS IMU) is learned only when a
scan constrains x and y, and the velocity drifts with it meanwhile. Every scan is then

1. deskewed to its stamp with the IMU's motion over the sweep (each point moved from its
   own instant, the per-point time, with the mean rate and acceleration of the sweep);
2. down-sampled on ``voxel`` and registered point-to-plane against a local map of the
   scans before it, as the measurement of an iterated Kalman update (FAST-LIO's scheme:
   correspondences found again at every iteration, each kept within ``gate`` sigmas of
   what the prior pose covariance allows). Planes are fitted to the
   ``wide_points`` nearest map points within ``wide_reach`` where they are flat, else to
   the ``neighbours`` nearest within ``max_distance`` (five, FAST-LIO's choice): a ground
   point's five nearest lie along one scan ring (a line, refused), twenty span rings.
   Directions of the pose a scan informs less than ``least`` keep the IMU's prediction
   (:func:`~alte.registration.inertial.strong_directions`): over flat ground x, y and yaw
   get only the false information of normals tilted by noise, which the filter would
   fold into velocity and accelerometer bias; LiDAR-only odometry slides there;
3. added to the map (``voxel / 2`` grid, points beyond ``max_range`` of the vehicle dropped)
   with the filter's position variance at that moment: a residual against a map point
   weighs as its plane noise plus where that point was placed
   (:mod:`~alte.registration.localmap`), so a wall the drift itself mapped does not
   shrink the along-track uncertainty it was mapped with.

The world frame is the first scan's body pose (the recorded one when the bag has poses,
else level from the accelerometer), gravity along -z; its heading is therefore known, and
the filter starts with a yaw uncertainty of 1 mrad
(:class:`~alte.registration.inertial.InertialFilter`). Two PyPI packages were tried first
(environment.md); both diverged on the simulated UAV missions.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from alte.errors import RegistrationError
from alte.params import Record, param
from alte.registration.inertial import (
    ImuNoise,
    InertialFilter,
    NavState,
    Residuals,
    integrate,
    still,
)
from alte.registration.localmap import LocalMap, voxel_first
from alte.types import Frame, Mount

if TYPE_CHECKING:
    from alte.io.bags.imu import ImuSamples
    from alte.registration.settings import PoseCounts

__all__ = ["LioOdometry", "LioSettings", "check_overlap", "lio_frames"]


def _positive(value: float) -> bool:
    return value > 0


@dataclass(frozen=True)
class LioSettings(Record):
    """What the LIO reads from :class:`~alte.registration.odometry.OdometrySettings`
    (``noise`` from its six IMU figures; ``gate``, ``gate_sigma`` and ``iterations`` are
    not settings of ``--odometry-set``); the rules are OdometrySettings'."""

    OWNER = "lio"

    voxel: float = param(0.5, _positive, "voxel > 0", "scan down-sampling voxel (m); the "
                                                      "map's is half of it")
    max_range: float = param(100.0, _positive, "max_range > 0",
                             "points beyond are not used, nor kept in the map (m)")
    min_range: float = param(1.0, lambda v: v >= 0, "min_range >= 0",
                             "nearer points are not used (m)")
    plane_sigma: float = param(0.15, _positive, "plane_sigma > 0",
                               "point-to-plane noise, the Cauchy kernel width (m)")
    max_distance: float = param(2.0, _positive, "max_distance > 0",
                                "farthest map neighbour of a small plane fit (m)")
    neighbours: int = param(5, lambda v: v >= 3, "neighbours >= 3",
                            "map points of a small plane fit")
    wide_points: int = param(20, lambda v: v == 0 or v >= 3, "wide_points 0 or >= 3",
                             "map points of the plane fit across scan rings (0: small only)")
    wide_reach: float = param(3.0, _positive, "wide_reach > 0",
                              "farthest map neighbour of the plane fit across rings (m)")
    least: float = param(30.0, lambda v: v >= 0, "least >= 0",
                         "least information a scan gives a pose direction for the update "
                         "to move it (1/m^2; 0: every direction)")
    gate: float = param(3.0, _positive, "gate > 0",
                        "a correspondence is kept within that many sigmas of the prior pose")
    gate_sigma: float = param(0.05, _positive, "gate_sigma > 0",
                              "point and plane noise the gate allows for (m)")
    iterations: int = param(5, lambda v: v >= 1, "iterations >= 1",
                            "iterated Kalman updates per scan")
    noise: ImuNoise = param(ImuNoise(), help="the IMU's noise figures")


def _matrix(position: NDArray[np.float64], rotation: Rotation[tuple[()]]) -> NDArray[np.float64]:
    out = np.eye(4)
    out[:3, :3], out[:3, 3] = rotation.as_matrix(), position
    return out


def check_overlap(imu: ImuSamples, stamp: int) -> None:
    """Raise when the IMU does not cover a scan stamp (another clock or unit)."""
    lo, hi = int(imu.stamps[0]), int(imu.stamps[-1])
    if not lo - 1_000_000_000 <= stamp <= hi + 1_000_000_000:
        raise RegistrationError(
            f"odometry: method=lio: scan stamp {stamp} ns lies outside the IMU topic's "
            f"{lo}..{hi} ns (another clock or unit?); use method=kiss",
            setting="odometry.method")


class LioOdometry:
    """The filter, the map and the LiDAR's pose on the IMU (module docstring)."""

    def __init__(self, imu: ImuSamples, lidar: Mount, settings: LioSettings,
                 start: tuple[NDArray[np.float64], NDArray[np.float64]] | None, first: int) -> None:
        self.imu, self.settings = imu, settings
        imu_mount = imu.mount or Mount()
        self.body_imu = _matrix(imu_mount.translation, imu_mount.rotation)
        self.imu_lidar = np.linalg.inv(self.body_imu) @ _matrix(lidar.translation,
                                                                lidar.rotation)
        rest = self._rest(first)
        body = self._level(first, rest) if start is None \
            else _matrix(start[0], Rotation.from_quat(start[1]))
        world_imu = body @ self.body_imu
        state = NavState(first, Rotation.from_matrix(world_imu[:3, :3]), world_imu[:3, 3],
                         np.zeros(3), np.zeros(3), np.zeros(3))
        self.rest_s = 0.0 if rest is None else \
            (int(imu.stamps[rest.stop - 1]) - int(imu.stamps[rest.start])) / 1e9
        self.filter = InertialFilter(state if rest is None else
                                     self._at_rest(state, rest, turn=start is not None),
                                     settings.noise)
        if rest is not None:  # static initialisation, then on to the first scan
            self.filter.settle(self.imu.angular_velocity[rest],
                               self.imu.linear_acceleration[rest])
            self._predict(first)
        self.map = LocalMap(settings.voxel / 2, settings.max_range)

    def _rest(self, stamp: int) -> slice[int, int] | None:
        """The IMU samples of the 2 s before the first scan while the vehicle was still
        (:func:`~alte.registration.inertial.still`), else None."""
        end = int(np.searchsorted(self.imu.stamps, stamp))
        begin = int(np.searchsorted(self.imu.stamps, stamp - 2_000_000_000))
        window = slice(begin, end)
        count = still(self.imu.angular_velocity[window], self.imu.linear_acceleration[window],
                      self.settings.noise, self.imu.rate_hz) if end - begin > 1 else 0
        return slice(begin, begin + count) if count else None

    def _at_rest(self, state: NavState, rest: slice[int, int], *, turn: bool) -> NavState:
        """``state`` (at the first scan) moved back to the end of the rest: with ``turn``
        (a recorded attitude), turned back by what the gyroscope saw since."""
        end = int(self.imu.stamps[rest.stop - 1])
        out = state.copy()
        out.stamp = end
        if turn:
            bias = self.imu.angular_velocity[rest].mean(axis=0)
            since = NavState(end, Rotation.identity(), np.zeros(3), np.zeros(3), bias,
                             np.zeros(3))
            span = self._window(end, state.stamp)
            moved = integrate(since, state.stamp, self.imu.stamps[span],
                              self.imu.angular_velocity[span],
                              self.imu.linear_acceleration[span])
            out.rotation = state.rotation * moved.rotation.inv()
        return out

    def _level(self, stamp: int, rest: slice[int, int] | None) -> NDArray[np.float64]:
        """A body pose at the origin, level by the mean specific force at rest before the
        first scan, else over the first 0.1 s."""
        near = np.abs(self.imu.stamps - stamp) <= 50_000_000
        force = self.imu.linear_acceleration[rest if rest is not None else near
                                             if near.any() else slice(0, 1)].mean(axis=0)
        up = self.body_imu[:3, :3] @ force
        tilt, _ = Rotation.align_vectors([[0.0, 0.0, 1.0]], [up])
        return _matrix(np.zeros(3), tilt)

    def _window(self, start: int, end: int) -> slice[int, int]:
        """Samples that can cover ``[start, end]`` (one either side)."""
        lo = max(int(np.searchsorted(self.imu.stamps, start)) - 1, 0)
        hi = int(np.searchsorted(self.imu.stamps, end)) + 1
        return slice(lo, hi)

    def _predict(self, stamp: int) -> None:
        """The filter carried to ``stamp`` (ns) by the IMU."""
        span = self._window(self.filter.state.stamp, stamp)
        self.filter.predict(stamp, self.imu.stamps[span], self.imu.angular_velocity[span],
                            self.imu.linear_acceleration[span])

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
        """Point-to-plane residuals of ``scan`` at a state, gated and whitened. A residual
        is kept within ``gate`` sigmas of what the prior pose covariance, ``gate_sigma``
        of point and plane noise and the map's own uncertainty allow (a plane fitted
        across a wall's foot and the ground, or a parallel face 0.5 m off, reads as a
        rotation of tenths of a degree); it weighs as ``plane_sigma`` against that noise
        plus where the map point was placed (:mod:`~alte.registration.localmap`)."""
        settings = self.settings
        prior = self.filter.cov[:6, :6].copy()

        def residuals(state: NavState) -> Residuals:
            rot = state.rotation.as_matrix()
            world = scan @ rot.T + state.position
            fit = self.map.planes(world, settings.max_distance, settings.neighbours,
                                  (settings.wide_points, settings.wide_reach))
            r = np.einsum("ij,ij->i", fit.normal, world[fit.index] - fit.centre)
            # d r / d theta = -n^T R [q]x ; d r / d p = n^T
            jac = np.hstack([np.cross(scan[fit.index], fit.normal @ rot), fit.normal])
            spread = settings.gate_sigma**2 + fit.variance \
                + np.einsum("ij,jk,ik->i", jac, prior, jac)
            keep = (np.abs(r) < settings.max_distance / 2) \
                & (r**2 < settings.gate**2 * spread)
            scale = settings.plane_sigma / np.sqrt(settings.plane_sigma**2 + fit.variance[keep])
            return r[keep] * scale, jac[keep] * scale[:, None]

        return residuals

    def step(self, frame: Frame) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """The body pose (4x4, world) at the frame's stamp, and the scan deskewed to the
        stamp (LiDAR frame, every point in its order: the cloud the map is built from)."""
        check_overlap(self.imu, frame.stamp)
        self._predict(frame.stamp)
        points = np.asarray(frame.points, dtype=np.float64)
        ranges = np.linalg.norm(points, axis=1)
        keep = np.isfinite(ranges) & (ranges >= self.settings.min_range) \
            & (ranges <= self.settings.max_range)
        moved = self.deskew(points, None if frame.times is None else np.asarray(frame.times))
        scan = moved[keep]
        if self.map.ready:
            self.filter.update(self._residuals(voxel_first(scan, self.settings.voxel)),
                               self.settings.plane_sigma, self.settings.iterations,
                               least=self.settings.least)
        state = self.filter.state
        self.map.add(scan @ state.rotation.as_matrix().T + state.position, state.position,
                     np.diag(self.filter.cov[3:6, 3:6]))
        lidar = (moved - self.imu_lidar[:3, 3]) @ self.imu_lidar[:3, :3]
        return state.matrix() @ np.linalg.inv(self.body_imu), lidar


def lio_frames(frames: Iterable[Frame], lidar: Mount, imu: ImuSamples, settings: LioSettings,
               start: tuple[NDArray[np.float64], NDArray[np.float64]] | None = None,
               *, counts: PoseCounts | None = None,
               ) -> Iterator[tuple[Frame, NDArray[np.float64], NDArray[np.float64]]]:
    """Each frame with its body pose (4x4) from LIO, anchored at ``start``, and its points
    deskewed to the stamp by the IMU (:meth:`LioOdometry.step`); ``counts`` gets how long
    the IMU was still before the first scan."""
    odometry: LioOdometry | None = None
    for frame in frames:
        if odometry is None:
            check_overlap(imu, frame.stamp)
            odometry = LioOdometry(imu, lidar, settings, start, frame.stamp)
            if counts is not None:
                counts.rest_s = odometry.rest_s
        yield frame, *odometry.step(frame)
