"""The LiDAR odometry backends behind :func:`alte.registration.odometry.odometry_frames`.

* :class:`Kiss`: KISS-ICP (Vizzo et al., RA-L 2023) as its own pipeline runs it: range
  filter, deskew with per-point time, double down-sampling, adaptive threshold, its map
  voxel ``max_range / 100`` with 20 points a voxel. When the window
  (:mod:`~alte.registration.window`) follows it, which re-aligns every pose, its map is
  coarser (voxel ``1.5 x max_range / 100``, 10 points a voxel): on the real ``balm_seq``
  the pair lands as close to the reference as with KISS-ICP's own map at a third of its
  CPU (docs/results/poses.md); the registration's nearest-neighbour search over 27 voxels
  of up to that many points is what KISS-ICP spends its time on. Two switches follow its
  maintainers' advice for sparse (16-beam, Livox) sensors: ``single_downsample``
  registers the 0.5-voxel cloud instead of the 1.5-voxel one (PRBonn/kiss-icp#128) and
  ``fixed_threshold`` replaces the adaptive one (PRBonn/kiss-icp#146).
* :class:`Plane`: each scan aligned point-to-plane (Open3D) to a local map of the
  scans before it (:class:`PlaneMap`), from a constant-velocity guess.

A backend is made from the first scan (its ranges scale what is left unset) and steps
one scan at a time, returning the sensor pose in the first scan's sensor frame.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Protocol

import numpy as np
from numpy.typing import NDArray

if TYPE_CHECKING:
    import open3d as o3d

    from alte.registration.settings import OdometrySettings, PoseCounts

__all__ = ["KISS_POINTS", "KISS_VOXEL_SCALE", "Kiss", "Plane", "PlaneMap", "kiss_config",
           "kiss_points", "kiss_voxel", "scene_scale", "window_voxel"]


class _KissData(Protocol):
    """What is read of KISS-ICP's ``config.data``."""

    deskew: bool


class _KissMapping(Protocol):
    """What is read of KISS-ICP's ``config.mapping``."""

    voxel_size: float


class KissSettings(Protocol):
    """What alte reads of a ``kiss_icp.config.KISSConfig`` (kiss-icp ships no types)."""

    @property
    def data(self) -> _KissData: ...
    @property
    def mapping(self) -> _KissMapping: ...


def scene_scale(points: NDArray[np.float64], params: OdometrySettings) -> tuple[float, float]:
    """(max range, voxel) for a scan in the sensor frame: ``max_range`` (default KISS-ICP's
    100 m for ``kiss``, 1.2 x the 99th percentile range for ``plane``) and ``voxel``
    (default :func:`kiss_voxel` for ``kiss``, the median range / 70 for ``plane``)."""
    ranges = np.linalg.norm(np.asarray(points, dtype=np.float64), axis=1)
    ranges = ranges[np.isfinite(ranges)]
    if params.method == "kiss":
        return params.max_range or 100.0, kiss_voxel(params)
    typical = float(np.median(ranges)) if len(ranges) else 10.0
    far = float(np.percentile(ranges, 99)) if len(ranges) else 100.0
    max_range = params.max_range or max(1.2 * far, 1.0)
    return max_range, params.voxel or max(typical / 70, 0.01)


#: KISS-ICP's map voxel with the window after it, in units of its own rule
#: (``max_range / 100``), and its points a voxel then (module docstring).
KISS_VOXEL_SCALE, KISS_POINTS = 1.5, 10


def kiss_voxel(params: OdometrySettings) -> float:
    """KISS-ICP's map voxel for ``params``: ``voxel``, else ``max_range / 100`` (1 m at its
    default range of 100 m), 1.5 times that when the window follows (module docstring)."""
    scale = KISS_VOXEL_SCALE if params.window > 0 else 1.0
    return params.voxel or scale * (params.max_range or 100.0) / 100.0


def kiss_points(params: OdometrySettings) -> int:
    """KISS-ICP's map points per voxel: ``max_points_per_voxel``, else its own 20, 10 when
    the window follows (module docstring)."""
    return params.max_points_per_voxel or (KISS_POINTS if params.window > 0 else 20)


def window_voxel(params: OdometrySettings) -> float:
    """The window's Gaussian voxel: ``window_voxel``, else KISS-ICP's own map voxel rule,
    ``max_range / 100`` (1 m at its default range)."""
    return params.window_voxel or (params.max_range or 100.0) / 100.0


def kiss_config(points: NDArray[np.float64], params: OdometrySettings,
                timed: bool = False) -> KissSettings:
    """KISS-ICP's configuration for ``params`` (unset values: KISS-ICP's own defaults);
    deskewing only for scans with per-point time (``timed``)."""
    from kiss_icp.config import KISSConfig

    max_range, voxel = scene_scale(points, params)
    config = KISSConfig()
    config.data.deskew = params.deskew and timed
    config.data.max_range = max_range
    config.data.min_range = params.min_range
    config.mapping.voxel_size = voxel
    config.mapping.max_points_per_voxel = kiss_points(params)
    config.adaptive_threshold.initial_threshold = params.initial_threshold
    config.adaptive_threshold.min_motion_th = params.min_motion_th
    config.adaptive_threshold.fixed_threshold = params.fixed_threshold
    config.registration.max_num_threads = params.threads
    settings: KissSettings = config
    return settings


class Kiss:
    """KISS-ICP's own pipeline, with the sparse-sensor switches (module docstring)."""

    def __init__(self, points: NDArray[np.float64], params: OdometrySettings, timed: bool) -> None:
        from kiss_icp.kiss_icp import KissICP
        from kiss_icp.voxelization import voxel_down_sample

        self.config = config = kiss_config(points, params, timed)
        self.pipeline = KissICP(config)
        if params.single_downsample:
            voxel = config.mapping.voxel_size

            def single(frame: NDArray[np.float64],
                       ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
                down = voxel_down_sample(frame, 0.5 * voxel)
                return down, down

            self.pipeline.voxelize = single

    def deskews(self, times: NDArray[np.float64] | None) -> bool:
        """Whether a scan with these per-point ``times`` is deskewed (they must vary)."""
        return bool(times is not None and self.config.data.deskew and len(times)
                    and np.ptp(times) > 0)

    def step(self, points: NDArray[np.float64], times: NDArray[np.float64] | None,
             ) -> NDArray[np.float64]:
        """The sensor pose of this scan in the first scan's sensor frame (deskewed with
        ``times`` when given and ``deskew`` is on)."""
        stamps = times if times is not None and self.deskews(times) else np.zeros(len(points))
        self.pipeline.register_frame(points, stamps)
        return np.asarray(self.pipeline.last_pose)


class PlaneMap:
    """Registered scans near the sensor as an Open3D point-to-plane target.

    Normals come from a radius of ``6 * voxel`` (a few scan rings: the neighbours of a
    point on one ring lie on a line, which gives no plane), correspondences up to
    ``6 * voxel`` with a Tukey kernel. New scans join the map every ``rebuild`` scans.
    """

    def __init__(self, voxel: float, radius: float, rebuild: int) -> None:
        self.voxel, self.radius, self.rebuild = voxel, radius, rebuild
        self.points = np.empty((0, 3))
        self.pending: list[NDArray[np.float64]] = []
        self.target: o3d.geometry.PointCloud | None = None

    def source(self, scan: NDArray[np.float64]) -> o3d.geometry.PointCloud:
        """The scan (sensor frame) down-sampled on the map's voxel."""
        import open3d as o3d

        cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(scan))
        return cloud.voxel_down_sample(self.voxel)

    def add(self, source: o3d.geometry.PointCloud, sensor: NDArray[np.float64]) -> None:
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

    def align(self, source: o3d.geometry.PointCloud, guess: NDArray[np.float64],
              ) -> tuple[NDArray[np.float64], float]:
        """The sensor pose placing ``source`` on the map, from ``guess``; inlier fraction."""
        import open3d as o3d

        assert self.target is not None  # Plane aligns only once the map has a target
        reg = o3d.pipelines.registration
        reach = 6.0 * self.voxel
        method = reg.TransformationEstimationPointToPlane(reg.TukeyLoss(k=reach / 2))
        result = reg.registration_icp(source, self.target, reach, guess, method,
                                      reg.ICPConvergenceCriteria(max_iteration=30))
        return np.asarray(result.transformation), float(result.fitness)


class Plane:
    """Point-to-plane scan-to-map odometry from a constant-velocity guess."""

    def __init__(self, points: NDArray[np.float64], params: OdometrySettings,
                 counts: PoseCounts) -> None:
        max_range, voxel = scene_scale(points, params)
        self.map = PlaneMap(voxel, max_range, params.rebuild)
        self.params, self.counts = params, counts
        self.pose, self.motion = np.eye(4), np.eye(4)

    def step(self, points: NDArray[np.float64], times: NDArray[np.float64] | None,
             ) -> NDArray[np.float64]:
        """The sensor pose of this scan (``times`` unused: no deskew)."""
        del times
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
