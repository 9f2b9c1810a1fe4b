"""Poses from the LiDAR itself: odometry when a bag has none, refinement when they are late.

* :func:`odometry_frames`: scan-by-scan LiDAR odometry as the frames stream, anchored
  at ``start`` (the first scan's body pose: identity, or the recorded pose there).
  ``method=kiss``: KISS-ICP (Vizzo et al., RA-L 2023; deskewing off: the clouds carry
  no per-point time; voxel and thresholds scaled to the scene, its defaults being for
  100 m outdoor ranges). ``method=plane``: each scan aligned point-to-plane to a local
  map of the scans before it (:class:`_PlaneMap`), from a constant-velocity guess.
  KISS-ICP matches points to points; on a down-tilted scanner over a floor the rings
  of consecutive scans fall on one another and hold the estimate back, while
  point-to-plane leaves the floor free to slide under the scan (``alte odometry``).
* :func:`refine_frames`: each recorded pose aligned scan-to-map (small_gicp
  point-to-plane ICP against every earlier refined scan, :class:`_DenseMap`); this
  corrects desynchronised poses (thesis fig. 4.34). A correction above the bound, or
  an alignment with too few inliers, is not applied (the recorded pose is kept) and
  is counted.

Every frame goes through: nothing is dropped here, only counted (:class:`PoseCounts`).
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, replace
from typing import Any, ClassVar

import numpy as np
from scipy.spatial.transform import Rotation

from alte.params import Record, param
from alte.types import Frame, Mount

__all__ = ["METHODS", "OdometryParams", "PoseCounts", "odometry_frames", "pose_matrix",
           "refine_frames", "scene_scale"]

#: Odometry backends (module docstring).
METHODS = ("plane", "kiss")
#: Threads small_gicp may use (its default is one).
_THREADS = max(1, min(8, os.cpu_count() or 1))


def _positive(value: float) -> bool:
    return value > 0


@dataclass(frozen=True)
class OdometryParams(Record):
    """How scans are aligned (None: from the first scan's ranges, module docstring)."""

    OWNER: ClassVar[str] = "odometry"
    method: str = param("plane", lambda v: v in METHODS, "plane|kiss", "odometry backend")
    max_range: float | None = param(None, _positive, "> 0",
                                    "m; map radius and KISS-ICP range (default 1.2 x the 99th "
                                    "percentile range of the first scan)")
    voxel: float | None = param(None, _positive, "> 0",
                                "m; map voxel (default: plane median range / 70, kiss "
                                "max_range / 100)")
    rebuild: int = param(5, lambda v: v >= 1, ">= 1", "scans between local-map rebuilds")
    min_fitness: float = param(0.3, lambda v: 0 <= v <= 1, "0..1",
                               "fewest inliers (fraction of the scan) for an alignment to count")
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
    weak_alignments: int = 0
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


def scene_scale(points: np.ndarray, params: OdometryParams) -> tuple[float, float]:
    """(max range, map voxel) for a scan in the sensor frame."""
    ranges = np.linalg.norm(np.asarray(points, dtype=np.float64), axis=1)
    ranges = ranges[np.isfinite(ranges)]
    typical = float(np.median(ranges)) if len(ranges) else 10.0
    far = float(np.percentile(ranges, 99)) if len(ranges) else 100.0
    max_range = params.max_range or max(1.2 * far, 1.0)
    if params.voxel:
        return max_range, params.voxel
    return max_range, max_range / 100.0 if params.method == "kiss" else max(typical / 70, 0.01)


class _PlaneMap:
    """Registered scans near the sensor as an Open3D point-to-plane target.

    Normals come from a radius of ``6 * voxel`` (a few scan rings: the neighbours of a
    point on one ring lie on a line, which gives no plane), correspondences up to
    ``6 * voxel`` with a Tukey kernel. New scans join the map every ``rebuild`` scans.
    """

    def __init__(self, voxel: float, radius: float, rebuild: int) -> None:
        self.voxel, self.radius, self.rebuild = voxel, radius, rebuild
        self.points = np.empty((0, 3))
        self.pending: list[np.ndarray] = []
        self.target: Any = None

    def source(self, scan: np.ndarray) -> Any:
        """The scan (sensor frame) down-sampled on the map's voxel."""
        import open3d as o3d

        cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(scan))
        return cloud.voxel_down_sample(self.voxel)

    def add(self, source: Any, sensor: np.ndarray) -> None:
        """Queue the aligned scan; rebuild the target when ``rebuild`` scans are queued."""
        import open3d as o3d

        self.pending.append(np.asarray(source.points) @ sensor[:3, :3].T + sensor[:3, 3])
        if self.target is not None and len(self.pending) < self.rebuild:
            return
        merged = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(
            np.vstack([self.points, *self.pending]))).voxel_down_sample(self.voxel)
        near = np.linalg.norm(np.asarray(merged.points) - sensor[:3, 3], axis=1) <= self.radius
        target = merged.select_by_index(np.flatnonzero(near).tolist())
        target.estimate_normals(o3d.geometry.KDTreeSearchParamHybrid(6.0 * self.voxel, 40))
        self.points, self.pending, self.target = np.asarray(target.points), [], target

    def align(self, source: Any, guess: np.ndarray) -> tuple[np.ndarray, float]:
        """The sensor pose placing ``source`` on the map, from ``guess``; inlier fraction."""
        import open3d as o3d

        reg = o3d.pipelines.registration

        reach = 6.0 * self.voxel
        method = reg.TransformationEstimationPointToPlane(reg.TukeyLoss(k=reach / 2))
        result = reg.registration_icp(source, self.target, reach, guess, method,
                                      reg.ICPConvergenceCriteria(max_iteration=30))
        return np.asarray(result.transformation), float(result.fitness)


class _DenseMap:
    """Refinement target: registered scans kept at ``voxel / 2``, matched point-to-plane
    (small_gicp) at ``voxel`` with normals from 20 neighbours; dense because many
    scans from nearby poses fill the gaps between one scan's rings. The target (grid,
    k-d tree, normals) is rebuilt every ``rebuild`` scans."""

    def __init__(self, voxel: float, radius: float, rebuild: int) -> None:
        self.voxel, self.radius, self.rebuild = voxel, radius, rebuild
        self.points = np.empty((0, 3))
        self.added = 0
        self.target: Any = None

    def add(self, scan: np.ndarray, sensor: np.ndarray) -> None:
        """Add the scan (sensor frame) placed at ``sensor``; forget what is out of reach."""
        import small_gicp

        placed = scan @ sensor[:3, :3].T + sensor[:3, 3]
        merged = small_gicp.voxelgrid_sampling(np.vstack([self.points, placed]), self.voxel / 2,
                                               num_threads=_THREADS)
        pts = np.asarray(merged.points())[:, :3]
        self.points = pts[np.linalg.norm(pts - sensor[:3, 3], axis=1) <= self.radius]
        self.added += 1
        if self.target is None or self.added % self.rebuild == 0:
            target = small_gicp.voxelgrid_sampling(self.points, self.voxel, num_threads=_THREADS)
            tree = small_gicp.KdTree(target, num_threads=_THREADS)
            small_gicp.estimate_normals(target, tree, num_neighbors=20, num_threads=_THREADS)
            self.target = (target, tree)

    def align(self, scan: np.ndarray, guess: np.ndarray) -> tuple[np.ndarray, float]:
        """The sensor pose placing ``scan`` on the map from ``guess``; inlier fraction."""
        import small_gicp

        target, tree = self.target
        source = small_gicp.voxelgrid_sampling(scan, self.voxel, num_threads=_THREADS)
        result = small_gicp.align(target, source, tree, guess, registration_type="PLANE_ICP",
                                  max_correspondence_distance=6.0 * self.voxel,
                                  num_threads=_THREADS, max_iterations=30)
        return np.asarray(result.T_target_source), result.num_inliers / max(source.size(), 1)


class _Kiss:
    """KISS-ICP scaled to the scene of the first scan (module docstring)."""

    def __init__(self, points: np.ndarray, params: OdometryParams) -> None:
        from kiss_icp.config import KISSConfig
        from kiss_icp.kiss_icp import KissICP

        max_range, voxel = scene_scale(points, params)
        config = KISSConfig()
        config.data.deskew = False
        config.data.max_range = max_range
        config.mapping.voxel_size = voxel
        config.adaptive_threshold.initial_threshold = 2.0 * voxel
        config.adaptive_threshold.min_motion_th = 0.1 * voxel
        self.pipeline = KissICP(config)

    def step(self, points: np.ndarray) -> np.ndarray:
        """The sensor pose of this scan in the first scan's sensor frame."""
        self.pipeline.register_frame(points, np.zeros(len(points)))
        return np.asarray(self.pipeline.last_pose)


class _Plane:
    """Point-to-plane scan-to-map odometry from a constant-velocity guess."""

    def __init__(self, points: np.ndarray, params: OdometryParams, counts: PoseCounts) -> None:
        max_range, voxel = scene_scale(points, params)
        self.map = _PlaneMap(voxel, max_range, params.rebuild)
        self.params, self.counts = params, counts
        self.pose, self.motion = np.eye(4), np.eye(4)

    def step(self, points: np.ndarray) -> np.ndarray:
        source = self.map.source(points)
        guess = self.pose @ self.motion
        if self.map.target is not None:
            aligned, fitness = self.map.align(source, guess)
            if fitness >= self.params.min_fitness:
                guess = aligned
            else:
                self.counts.weak_alignments += 1
        self.motion = np.linalg.inv(self.pose) @ guess if self.map.target is not None \
            else np.eye(4)
        self.pose = guess
        self.map.add(source, guess)
        return guess


def _rate(previous: Frame | None, quaternion: np.ndarray, stamp: int) -> float:
    """Body angular rate (rad/s) from the previous odometry pose (0 for the first)."""
    if previous is None or stamp == previous.stamp:
        return 0.0
    turn = previous.rotation.inv() * Rotation.from_quat(quaternion)
    return float(turn.magnitude() / abs(stamp - previous.stamp) * 1e9)


def odometry_frames(frames: Iterable[Frame], mount: Mount, *, counts: PoseCounts,
                    params: OdometryParams | None = None,
                    start: tuple[np.ndarray, np.ndarray] | None = None) -> Iterator[Frame]:
    """``frames`` with body poses from LiDAR odometry, anchored at ``start``."""
    params = params or OdometryParams()
    body_sensor = pose_matrix(mount.translation, mount.quaternion)
    sensor_body = np.linalg.inv(body_sensor)
    anchor = (pose_matrix(*start) if start is not None else np.eye(4)) @ body_sensor
    odometry: _Kiss | _Plane | None = None
    previous: Frame | None = None
    for frame in frames:
        points = np.asarray(frame.points, dtype=np.float64)
        if odometry is None:
            odometry = _Kiss(points, params) if params.method == "kiss" \
                else _Plane(points, params, counts)
        position, quaternion = _pose(anchor @ odometry.step(points) @ sensor_body)
        counts.frames += 1
        previous = replace(frame, position=position, quaternion=quaternion, pose_offset_s=0.0,
                           angular_rate=_rate(previous, quaternion, frame.stamp))
        yield previous


def _correction(guess: np.ndarray, aligned: np.ndarray) -> tuple[float, float]:
    """Size of ``guess -> aligned``: metres and degrees."""
    delta = np.linalg.inv(guess) @ aligned
    angle = Rotation.from_matrix(delta[:3, :3]).magnitude()
    return float(np.linalg.norm(delta[:3, 3])), float(np.degrees(angle))


def refine_frames(frames: Iterable[Frame], mount: Mount, *, counts: PoseCounts,
                  params: OdometryParams | None = None) -> Iterator[Frame]:
    """``frames`` with each recorded pose aligned scan-to-map (module docstring)."""
    params = params or OdometryParams()
    body_sensor = pose_matrix(mount.translation, mount.quaternion)
    sensor_body = np.linalg.inv(body_sensor)
    local: _DenseMap | None = None
    for frame in frames:
        points = np.asarray(frame.points, dtype=np.float64)
        sensor = pose_matrix(frame.position, frame.quaternion) @ body_sensor
        counts.frames += 1
        if local is None:
            max_range, voxel = scene_scale(points, replace(params, method="plane"))
            local = _DenseMap(voxel, max_range, params.rebuild)
        else:
            sensor = _refined(local, points, sensor, counts, params)
        local.add(points, sensor)
        position, quaternion = _pose(sensor @ sensor_body)
        yield replace(frame, position=position, quaternion=quaternion)


def _refined(local: _DenseMap, points: np.ndarray, guess: np.ndarray, counts: PoseCounts,
             params: OdometryParams) -> np.ndarray:
    """The aligned sensor pose, or ``guess`` when the alignment is weak or went too far."""
    aligned, fitness = local.align(points, guess)
    if fitness < params.min_fitness:
        counts.weak_alignments += 1
        return guess
    metres, degrees = _correction(guess, aligned)
    if metres > params.max_correction or degrees > params.max_correction_deg:
        counts.corrections_above_bound += 1
        return guess
    counts.corrected += 1
    counts.max_correction_m = max(counts.max_correction_m, metres)
    counts.max_correction_deg = max(counts.max_correction_deg, degrees)
    return aligned
