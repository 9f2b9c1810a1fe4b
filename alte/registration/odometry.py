"""Poses from the LiDAR itself: odometry when a bag has none, refinement when they are late.

* :func:`odometry_frames`: scan-by-scan LiDAR odometry as the frames stream, anchored
  at ``start`` (the first scan's body pose: identity, or the recorded pose there),
  with one of the backends of :mod:`alte.registration.backends` (``kiss``: KISS-ICP
  with its own defaults; ``plane``: point-to-plane scan-to-map ICP) or LiDAR-inertial
  odometry (``lio``, :mod:`alte.registration.lio`) with the bag's IMU. ``auto``, the
  default, is ``lio`` when the bag has an IMU topic and ``kiss`` otherwise
  (:func:`resolve_method`). Scans that carry per-point time are deskewed: for the
  alignment (KISS-ICP's own deskew, or the IMU's motion over the sweep) and for the map
  (the frames carry the scan moved to its stamp: LIO's deskewed scan, else the constant
  motion between the backend's last two poses; the first scan of a LiDAR-only run as
  taken).
* :func:`~alte.registration.refine.refine_frames`: recorded poses aligned scan-to-map,
  a correction applied only when it is well constrained and clearly better.

The defaults were chosen on the real ``balm_seq`` recording (``alte odometry``; the
documentation's results page on poses). Every frame goes through: nothing is dropped
here, only counted (:class:`PoseCounts`).
"""

from __future__ import annotations

import time
from collections.abc import Iterable, Iterator
from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from alte.errors import ParameterError
from alte.registration.backends import Kiss, Plane, window_voxel
from alte.registration.deskew import deskew_constant_velocity
from alte.registration.inertial import ImuNoise
from alte.registration.lio import LioSettings, lio_frames
from alte.registration.refine import refine_frames
from alte.registration.settings import (
    KEYS,
    METHODS,
    OdometrySettings,
    PoseCounts,
    odometry_label,
    odometry_params,
    pose_matrix,
    resolve_method,
)
from alte.registration.window import window_poses
from alte.types import Frame, Mount

if TYPE_CHECKING:
    from alte.io.bags.imu import ImuSamples

__all__ = ["KEYS", "METHODS", "OdometrySettings", "PoseCounts", "lio_settings", "odometry_frames",
           "odometry_label", "odometry_params", "pose_matrix", "refine_frames", "resolve_method"]

def lio_settings(params: OdometrySettings) -> LioSettings:
    """What :mod:`alte.registration.lio` reads of ``params`` (unset: its defaults)."""
    base = LioSettings()
    return LioSettings(voxel=params.voxel or base.voxel,
                       max_range=params.max_range or base.max_range,
                       min_range=params.min_range, plane_sigma=params.plane_sigma,
                       max_distance=params.plane_reach, neighbours=params.plane_points,
                       wide_points=params.wide_points, wide_reach=params.wide_reach,
                       least=params.least,
                       noise=ImuNoise(gyro=params.gyro_noise, accel=params.accel_noise,
                                      gyro_walk=params.gyro_walk, accel_walk=params.accel_walk,
                                      gyro_bias=params.gyro_bias, accel_bias=params.accel_bias))


def _rate(previous: Frame | None, quaternion: NDArray[np.float64], stamp: int) -> float:
    """Body angular rate (rad/s) from the previous odometry pose (0 for the first)."""
    if previous is None or stamp == previous.stamp:
        return 0.0
    turn = previous.rotation.inv() * Rotation.from_quat(quaternion)
    return float(turn.magnitude() / abs(stamp - previous.stamp) * 1e9)


def _posed(frame: Frame, body: NDArray[np.float64], previous: Frame | None) -> Frame:
    """``frame`` with the body pose ``body`` (4x4) and the rate since ``previous``."""
    quaternion = Rotation.from_matrix(body[:3, :3]).as_quat()
    return replace(frame, position=body[:3, 3].copy(), quaternion=quaternion,
                   pose_offset_s=0.0, angular_rate=_rate(previous, quaternion, frame.stamp))


def _lio_frames(frames: Iterable[Frame], mount: Mount, imu: ImuSamples | None, *,
                counts: PoseCounts, params: OdometrySettings,
                start: tuple[NDArray[np.float64], NDArray[np.float64]] | None) -> Iterator[Frame]:
    """``frames`` posed by LiDAR-inertial odometry (:mod:`alte.registration.lio`)."""
    if imu is None:
        raise ParameterError("odometry: method=lio needs an IMU topic (sensor_msgs/msg/Imu) "
                             "in the bag; use method=kiss", setting="odometry.method")
    previous: Frame | None = None
    steps = lio_frames(frames, mount, imu, lio_settings(params), start, counts=counts)
    while True:
        began, cpu = time.perf_counter(), time.thread_time()
        item = next(steps, None)
        if item is None:
            return
        counts.seconds += time.perf_counter() - began
        counts.cpu_seconds += time.thread_time() - cpu
        counts.frames += 1
        frame, body, points = item
        if frame.times is not None and len(frame.times) > 0:  # the cloud as the map saw it
            counts.deskewed += 1
            frame = replace(frame, points=points.astype(frame.points.dtype, copy=False),
                            times=None)
        previous = _posed(frame, body, previous)
        yield previous


def odometry_frames(frames: Iterable[Frame], mount: Mount, *, counts: PoseCounts,
                    params: OdometrySettings | None = None,
                    start: tuple[NDArray[np.float64], NDArray[np.float64]] | None = None,
                    imu: ImuSamples | None = None) -> Iterator[Frame]:
    """``frames`` with body poses from LiDAR (or LiDAR-inertial, with ``imu``) odometry,
    anchored at ``start``."""
    params = resolve_method(params or OdometrySettings(), imu is not None)
    counts.method, counts.settings = params.method, params.as_dict()
    if params.method == "lio":
        yield from _lio_frames(frames, mount, imu, counts=counts, params=params, start=start)
        return
    body_sensor = pose_matrix(mount.translation, mount.quaternion)
    sensor_body = np.linalg.inv(body_sensor)
    anchor = (pose_matrix(*start) if start is not None else np.eye(4)) @ body_sensor
    steps = _lidar_poses(frames, params, counts)
    if params.method == "kiss" and params.window > 0:
        steps = window_poses(steps, window=params.window, voxel=window_voxel(params),
                             min_fitness=params.min_fitness, counts=counts)
    previous: Frame | None = None
    before: tuple[int, NDArray[np.float64]] | None = None
    for frame, pose in steps:
        previous = _posed(_carried(frame, pose, before), anchor @ pose @ sensor_body, previous)
        before = (frame.stamp, pose)
        yield previous


def _carried(frame: Frame, pose: NDArray[np.float64],
             before: tuple[int, NDArray[np.float64]] | None) -> Frame:
    """``frame`` as the map gets it: with per-point time, its points moved to the stamp
    under the constant sensor motion since the scan ``before`` (its stamp and sensor pose;
    the backends deskew a copy for their own alignment only), else as taken."""
    if frame.times is None or before is None or frame.stamp == before[0]:
        return replace(frame, times=None)
    motion = np.linalg.inv(before[1]) @ pose
    points = deskew_constant_velocity(np.asarray(frame.points, dtype=np.float64),
                                      np.asarray(frame.times, dtype=np.float64), motion,
                                      (frame.stamp - before[0]) / 1e9)
    return replace(frame, points=points.astype(frame.points.dtype, copy=False), times=None)


def _lidar_poses(frames: Iterable[Frame], params: OdometrySettings, counts: PoseCounts,
                 ) -> Iterator[tuple[Frame, NDArray[np.float64]]]:
    """Each frame with its sensor pose in the first scan's sensor frame (kiss or plane)."""
    odometry: Kiss | Plane | None = None
    for frame in frames:
        points = np.asarray(frame.points, dtype=np.float64)
        began, cpu = time.perf_counter(), time.thread_time()
        if odometry is None:
            odometry = Kiss(points, params, frame.times is not None) \
                if params.method == "kiss" \
                else Plane(points, params, counts)
        pose = odometry.step(points, frame.times)
        counts.seconds += time.perf_counter() - began
        counts.cpu_seconds += time.thread_time() - cpu
        counts.frames += 1
        counts.deskewed += int(isinstance(odometry, Kiss) and odometry.deskews(frame.times))
        yield frame, np.asarray(pose, dtype=np.float64)
