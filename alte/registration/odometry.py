"""Poses from the LiDAR itself: odometry when a bag has none, refinement when they are late.

* :func:`odometry_frames`: KISS-ICP (Vizzo et al., RA-L 2023) run scan by scan as the
  frames stream; each scan's body pose is the sensor's odometry pose carried through
  the mount, anchored at ``start`` (the first scan's body pose: identity, or the
  recorded pose there). Deskewing is off: the clouds carry no per-point time. KISS-ICP's
  voxel and thresholds scale with the scene (its defaults are for 100 m outdoor
  ranges): voxel = max range / 100, from the first scan unless given.
* :func:`refine_frames`: each scan aligned to a local map of the scans before it
  (small_gicp point-to-plane ICP, normals from the map), starting at the recorded pose;
  this corrects desynchronised poses (thesis fig. 4.34). A correction above the bound
  is not applied (the recorded pose is kept) and is counted.

Every frame goes through: nothing is dropped here, only counted (:class:`PoseCounts`).
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from dataclasses import dataclass, replace
from typing import ClassVar, Protocol

import numpy as np
from scipy.spatial.transform import Rotation

from alte.params import Record, param
from alte.types import Frame, Mount

__all__ = ["OdometryParams", "PoseCounts", "odometry_frames", "pose_matrix", "refine_frames",
           "scene_scale"]


def _positive(value: float) -> bool:
    return value > 0


@dataclass(frozen=True)
class OdometryParams(Record):
    """How scans are aligned (None: from the first scan's ranges, module docstring)."""

    OWNER: ClassVar[str] = "odometry"
    max_range: float | None = param(None, _positive, "> 0",
                                    "m; longer returns ignored (default 1.2 x the 99th "
                                    "percentile range of the first scan)")
    voxel: float | None = param(None, _positive, "> 0",
                                "m; odometry map voxel (default max_range / 100)")
    refine_voxel: float | None = param(None, _positive, "> 0",
                                       "m; refinement down-sampling (default median range / 60)")
    max_correction: float = param(0.5, _positive, "> 0",
                                  "m; a larger refinement is not applied, only counted")
    max_correction_deg: float = param(20.0, _positive, "> 0",
                                      "deg; a larger refinement is not applied, only counted")


@dataclass
class PoseCounts:
    """Where the poses came from and what odometry / refinement did to them."""

    source: str = "recorded"
    frames: int = 0
    corrected: int = 0
    corrections_above_bound: int = 0
    not_converged: int = 0
    max_correction_m: float = 0.0
    max_correction_deg: float = 0.0

    def as_dict(self) -> dict[str, object]:
        """Counts by name (JSON-ready)."""
        return dict(vars(self))


def pose_matrix(position: np.ndarray, quaternion: np.ndarray) -> np.ndarray:
    """4x4 homogeneous transform of a position and an (x, y, z, w) quaternion."""
    out = np.eye(4)
    out[:3, :3] = Rotation.from_quat(quaternion).as_matrix()
    out[:3, 3] = position
    return out


def _pose(matrix: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    return matrix[:3, 3].copy(), Rotation.from_matrix(matrix[:3, :3]).as_quat()


def _mount(mount: Mount) -> np.ndarray:
    return pose_matrix(mount.translation, mount.quaternion)


def scene_scale(points: np.ndarray, params: OdometryParams) -> tuple[float, float, float]:
    """(max range, odometry voxel, refinement voxel) for a scan (sensor frame)."""
    ranges = np.linalg.norm(np.asarray(points, dtype=np.float64), axis=1)
    ranges = ranges[np.isfinite(ranges)]
    typical = float(np.median(ranges)) if len(ranges) else 10.0
    far = float(np.percentile(ranges, 99)) if len(ranges) else 100.0
    max_range = params.max_range or max(1.2 * far, 1.0)
    voxel = params.voxel or max_range / 100.0
    return max_range, voxel, params.refine_voxel or max(typical / 60.0, 0.01)


class _Odometry(Protocol):
    """What :func:`odometry_frames` uses of a ``kiss_icp.kiss_icp.KissICP`` pipeline."""

    last_pose: np.ndarray

    def register_frame(self, frame: np.ndarray, timestamps: np.ndarray) -> object: ...


def _kiss(points: np.ndarray, params: OdometryParams) -> _Odometry:
    """A KISS-ICP pipeline scaled to the scene of ``points``."""
    from kiss_icp.config import KISSConfig
    from kiss_icp.kiss_icp import KissICP

    max_range, voxel, _ = scene_scale(points, params)
    config = KISSConfig()
    config.data.deskew = False
    config.data.max_range = max_range
    config.mapping.voxel_size = voxel
    config.adaptive_threshold.initial_threshold = 2.0 * voxel
    config.adaptive_threshold.min_motion_th = 0.1 * voxel
    pipeline: _Odometry = KissICP(config)
    return pipeline


def _rate(previous: Frame | None, rotation: np.ndarray, stamp: int) -> float:
    """Body angular rate (rad/s) from the previous odometry pose (0 for the first)."""
    if previous is None or stamp == previous.stamp:
        return 0.0
    turn = previous.rotation.inv() * Rotation.from_quat(rotation)
    return float(turn.magnitude() / abs(stamp - previous.stamp) * 1e9)


def odometry_frames(frames: Iterable[Frame], mount: Mount, *, counts: PoseCounts,
                    params: OdometryParams | None = None,
                    start: tuple[np.ndarray, np.ndarray] | None = None) -> Iterator[Frame]:
    """``frames`` with body poses from KISS-ICP, anchored at ``start`` (module docstring)."""
    params = params or OdometryParams()
    body_sensor = _mount(mount)
    sensor_body = np.linalg.inv(body_sensor)
    anchor = pose_matrix(*start) if start is not None else np.eye(4)
    odometry: _Odometry | None = None
    previous: Frame | None = None
    for frame in frames:
        points = np.asarray(frame.points, dtype=np.float64)
        if odometry is None:
            odometry = _kiss(points, params)
        odometry.register_frame(points, np.zeros(len(points)))
        sensor = odometry.last_pose
        position, quaternion = _pose(anchor @ body_sensor @ sensor @ sensor_body)
        counts.frames += 1
        out = replace(frame, position=position, quaternion=quaternion, pose_offset_s=0.0,
                      angular_rate=_rate(previous, quaternion, frame.stamp))
        previous = out
        yield out


class _LocalMap:
    """Registered scans near the sensor, down-sampled, as a small_gicp target with normals."""

    def __init__(self, voxel: float, radius: float) -> None:
        self.voxel, self.radius = voxel, radius
        self.points = np.empty((0, 3))

    def add(self, points: np.ndarray, centre: np.ndarray) -> None:
        import small_gicp

        merged = small_gicp.voxelgrid_sampling(np.vstack([self.points, points]), self.voxel)
        pts = np.asarray(merged.points())[:, :3]
        self.points = pts[np.linalg.norm(pts - centre, axis=1) <= self.radius]

    def align(self, scan: np.ndarray, guess: np.ndarray) -> tuple[np.ndarray, bool]:
        """The sensor pose placing ``scan`` on the map, from ``guess``; converged flag."""
        import small_gicp

        target = small_gicp.PointCloud(self.points)
        small_gicp.estimate_normals(target, num_neighbors=20)
        source = small_gicp.voxelgrid_sampling(scan, self.voxel)
        result = small_gicp.align(target, source, small_gicp.KdTree(target), guess,
                                  registration_type="PLANE_ICP",
                                  max_correspondence_distance=6.0 * self.voxel,
                                  max_iterations=30)
        return np.asarray(result.T_target_source), bool(result.converged)


def _correction(guess: np.ndarray, aligned: np.ndarray) -> tuple[float, float]:
    """Size of ``guess -> aligned``: metres and degrees."""
    delta = np.linalg.inv(guess) @ aligned
    angle = Rotation.from_matrix(delta[:3, :3]).magnitude()
    return float(np.linalg.norm(delta[:3, 3])), float(np.degrees(angle))


def refine_frames(frames: Iterable[Frame], mount: Mount, *, counts: PoseCounts,
                  params: OdometryParams | None = None) -> Iterator[Frame]:
    """``frames`` with each recorded pose aligned scan-to-map (module docstring)."""
    params = params or OdometryParams()
    body_sensor = _mount(mount)
    sensor_body = np.linalg.inv(body_sensor)
    local: _LocalMap | None = None
    for frame in frames:
        points = np.asarray(frame.points, dtype=np.float64)
        guess = pose_matrix(frame.position, frame.quaternion) @ body_sensor
        counts.frames += 1
        if local is None:
            max_range, _, voxel = scene_scale(points, params)
            local = _LocalMap(voxel, max_range)
            sensor = guess
        else:
            sensor = _refined(local, points, guess, counts, params)
        local.add(points @ sensor[:3, :3].T + sensor[:3, 3], sensor[:3, 3])
        position, quaternion = _pose(sensor @ sensor_body)
        yield replace(frame, position=position, quaternion=quaternion)


def _refined(local: _LocalMap, points: np.ndarray, guess: np.ndarray, counts: PoseCounts,
             params: OdometryParams) -> np.ndarray:
    """The aligned sensor pose, or ``guess`` when the alignment failed or went too far."""
    aligned, converged = local.align(points, guess)
    metres, degrees = _correction(guess, aligned)
    if not converged:
        counts.not_converged += 1
        return guess
    if metres > params.max_correction or degrees > params.max_correction_deg:
        counts.corrections_above_bound += 1
        return guess
    counts.corrected += 1
    counts.max_correction_m = max(counts.max_correction_m, metres)
    counts.max_correction_deg = max(counts.max_correction_deg, degrees)
    return aligned
