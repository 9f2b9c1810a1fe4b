"""Refinement of recorded poses that never makes them worse.

Each scan is aligned point-to-plane (small_gicp) to a map of the scans before it, placed
with their refined poses (:class:`DenseMap`), starting from its recorded pose. The
alignment replaces the recorded pose only when all of these hold, else the recorded pose
is kept and the scan counted as kept with the first reason that failed:

``weak``
    fewer than ``min_fitness`` of the scan's points have a map point within reach;
``degenerate``
    the alignment is not constrained in every direction: the smallest eigenvalue of the
    Gauss-Newton Hessian (rotation scaled by the scan's median range, so both blocks are
    in metres) is below ``min_constraint`` times the largest (a floor alone leaves the
    scan free to slide);
``above_bound``
    the correction exceeds ``max_correction`` m or ``max_correction_deg``;
``no_gain``
    the truncated point-to-plane cost at the aligned pose is not at least ``min_gain``
    lower than at the recorded one (accurate poses stay as they are).

This corrects desynchronised poses (thesis fig. 4.34) and leaves good ones alone.
Every scan has a :class:`ScanDecision` in ``PoseCounts.scans``.
"""

from __future__ import annotations

import os
import time
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Protocol

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from alte.registration.backends import scene_scale
from alte.registration.settings import pose_matrix
from alte.types import Frame, Mount

if TYPE_CHECKING:
    from alte.registration.settings import OdometryParams, PoseCounts

__all__ = ["REASONS", "DenseMap", "ScanDecision", "refine_frames"]

#: Why a scan keeps its recorded pose (module docstring), in the order they are tested.
REASONS = ("first", "weak", "degenerate", "above_bound", "no_gain")
#: Correspondence reach, in map voxels.
_REACH = 4.0
#: Most points of a scan aligned (evenly spaced after the voxel grid): a few thousand
#: constrain six degrees of freedom as well as tens of thousands, at a fraction of the cost.
MAX_SOURCE = 5000


class GicpCloud(Protocol):
    """What is read of a small_gicp point cloud (small_gicp ships no types)."""

    def size(self) -> int: ...
    def points(self) -> NDArray[np.float64]: ...
    def normals(self) -> NDArray[np.float64]: ...


class _GicpTree(Protocol):
    """What is read of a small_gicp k-d tree."""

    def batch_nearest_neighbor_search(self, pts: NDArray[np.float64], num_threads: int = 1,
                                      ) -> tuple[list[int], list[float]]: ...


class GicpResult(Protocol):
    """What is read of a small_gicp registration result: the aligned pose (4x4) and the
    Gauss-Newton Hessian (6x6, rotation first)."""

    T_target_source: NDArray[np.float64]
    H: NDArray[np.float64]


def _threads(wanted: int) -> int:
    return wanted if wanted > 0 else max(1, os.cpu_count() or 1)


@dataclass(frozen=True)
class ScanDecision:
    """What refinement did to one scan: ``corrected`` or ``kept`` and why; the alignment's
    inlier fraction, cost gain (1 - aligned / recorded cost), constraint ratio and the
    size of the correction it proposed (applied only when ``corrected``)."""

    stamp: int
    decision: str
    reason: str
    fitness: float
    gain: float
    constraint: float
    metres: float
    degrees: float

    def as_dict(self) -> dict[str, object]:
        """JSON-ready."""
        return {k: (round(v, 6) if isinstance(v, float) else v) for k, v in vars(self).items()}


class DenseMap:
    """Refinement target: registered scans kept at ``voxel / 2`` within ``radius`` of the
    sensor, matched point-to-plane at ``voxel`` with normals from 20 neighbours (dense:
    many scans from nearby poses fill the gaps between one scan's rings). Scans are
    queued and the target (grid, k-d tree, normals) rebuilt every ``rebuild`` scans."""

    def __init__(self, voxel: float, radius: float, rebuild: int, threads: int) -> None:
        self.voxel, self.radius, self.rebuild = voxel, radius, rebuild
        self.threads = _threads(threads)
        self.points = np.empty((0, 3))
        self.pending: list[NDArray[np.float64]] = []
        self.target: tuple[GicpCloud, _GicpTree] | None = None

    def source(self, scan: NDArray[np.float64]) -> GicpCloud:
        """The scan down-sampled on the map voxel, at most :data:`MAX_SOURCE` points evenly
        spaced (a small_gicp cloud)."""
        import small_gicp

        grid: GicpCloud = small_gicp.voxelgrid_sampling(scan, self.voxel,
                                                        num_threads=self.threads)
        if grid.size() <= MAX_SOURCE:
            return grid
        points = np.asarray(grid.points())[:, :3]
        keep = np.linspace(0, len(points) - 1, MAX_SOURCE).astype(np.int64)
        spaced: GicpCloud = small_gicp.PointCloud(np.ascontiguousarray(points[keep]))
        return spaced

    def add(self, scan: NDArray[np.float64], sensor: NDArray[np.float64]) -> None:
        """Queue the scan (sensor frame, on a ``voxel / 2`` grid) placed at ``sensor``;
        rebuild the target every ``rebuild`` scans."""
        import small_gicp

        fine = small_gicp.voxelgrid_sampling(scan, self.voxel / 2, num_threads=self.threads)
        pts = np.asarray(fine.points())[:, :3]
        self.pending.append(pts @ sensor[:3, :3].T + sensor[:3, 3])
        if self.target is not None and len(self.pending) < self.rebuild:
            return
        merged = small_gicp.voxelgrid_sampling(np.vstack([self.points, *self.pending]),
                                               self.voxel / 2, num_threads=self.threads)
        pts = np.asarray(merged.points())[:, :3]
        self.points = pts[np.linalg.norm(pts - sensor[:3, 3], axis=1) <= self.radius]
        self.pending = []
        target = small_gicp.voxelgrid_sampling(self.points, self.voxel,
                                               num_threads=self.threads)
        tree = small_gicp.KdTree(target, num_threads=self.threads)
        small_gicp.estimate_normals(target, tree, num_neighbors=20, num_threads=self.threads)
        self.target = (target, tree)

    def align(self, source: GicpCloud, guess: NDArray[np.float64]) -> GicpResult:
        """small_gicp's point-to-plane alignment of ``source`` from ``guess``."""
        import small_gicp

        assert self.target is not None  # refine_frames aligns only once the map has a target
        target, tree = self.target
        result: GicpResult = small_gicp.align(
            target, source, tree, guess, registration_type="PLANE_ICP",
            max_correspondence_distance=_REACH * self.voxel, num_threads=self.threads,
            max_iterations=30)
        return result

    def cost(self, points: NDArray[np.float64], pose: NDArray[np.float64]) -> tuple[float, float]:
        """Inlier fraction and truncated point-to-plane cost (m^2, outliers at the reach)
        of sensor-frame ``points`` placed at ``pose``."""
        assert self.target is not None  # refine_frames aligns only once the map has a target
        target, tree = self.target
        placed = points @ pose[:3, :3].T + pose[:3, 3]
        found, sq = tree.batch_nearest_neighbor_search(placed, num_threads=self.threads)
        index = np.asarray(found, dtype=np.int64)
        reach = (_REACH * self.voxel) ** 2
        inlier = (np.asarray(sq) <= reach) & (index >= 0)
        ref = np.asarray(target.points())[:, :3][np.maximum(index, 0)]
        normal = np.asarray(target.normals())[:, :3][np.maximum(index, 0)]
        residual = np.einsum("ij,ij->i", normal, placed - ref) ** 2
        cost = np.where(inlier, np.minimum(residual, reach), reach)
        return float(inlier.mean()) if len(inlier) else 0.0, float(cost.mean()) \
            if len(cost) else reach


def _constraint(hessian: NDArray[np.float64], length: float) -> float:
    """Smallest over largest eigenvalue of the Hessian (rotation first, as small_gicp
    orders it) with rotation scaled to metres at ``length``."""
    scale = np.diag([1.0 / length] * 3 + [1.0] * 3)
    values = np.linalg.eigvalsh(scale @ np.asarray(hessian) @ scale)
    return float(max(values[0], 0.0) / values[-1]) if values[-1] > 0 else 0.0


def _correction(guess: NDArray[np.float64], aligned: NDArray[np.float64]) -> tuple[float, float]:
    """Size of ``guess -> aligned``: metres and degrees."""
    delta = np.linalg.inv(guess) @ aligned
    angle = Rotation.from_matrix(delta[:3, :3]).magnitude()
    return float(np.linalg.norm(delta[:3, 3])), float(np.degrees(angle))


def _decide(local: DenseMap, source: GicpCloud, guess: NDArray[np.float64], length: float,
            params: OdometryParams, *, stamp: int) -> tuple[NDArray[np.float64], ScanDecision]:
    """The pose to use for the scan and why (module docstring)."""
    result = local.align(source, guess)
    aligned = np.asarray(result.T_target_source)
    points = np.asarray(source.points())[:, :3]
    fitness, cost = local.cost(points, aligned)
    _, before = local.cost(points, guess)
    gain = 1.0 - cost / before if before > 0 else 0.0
    constraint = _constraint(result.H, length)
    metres, degrees = _correction(guess, aligned)
    checks = (("weak", fitness < params.min_fitness),
              ("degenerate", constraint < params.min_constraint),
              ("above_bound", metres > params.max_correction
               or degrees > params.max_correction_deg),
              ("no_gain", gain < params.min_gain))
    reason = next((name for name, failed in checks if failed), "")
    decision = ScanDecision(stamp, "kept" if reason else "corrected", reason, fitness, gain,
                            constraint, metres, degrees)
    return (guess if reason else aligned), decision


def _count(counts: PoseCounts, decision: ScanDecision) -> None:
    counts.scans.append(decision.as_dict())
    if decision.decision == "kept":
        counts.kept[decision.reason] = counts.kept.get(decision.reason, 0) + 1
        return
    counts.corrected += 1
    counts.max_correction_m = max(counts.max_correction_m, decision.metres)
    counts.max_correction_deg = max(counts.max_correction_deg, decision.degrees)


def refine_frames(frames: Iterable[Frame], mount: Mount, *, counts: PoseCounts,
                  params: OdometryParams) -> Iterator[Frame]:
    """``frames`` with each recorded pose refined when that is clearly better (module
    docstring)."""
    body_sensor = pose_matrix(mount.translation, mount.quaternion)
    sensor_body = np.linalg.inv(body_sensor)
    local: DenseMap | None = None
    length = 1.0
    for frame in frames:
        points = np.asarray(frame.points, dtype=np.float64)
        sensor = pose_matrix(frame.position, frame.quaternion) @ body_sensor
        counts.frames += 1
        began, cpu = time.perf_counter(), time.thread_time()
        if local is None:
            max_range, voxel = scene_scale(points, replace(params, method="plane"))
            local = DenseMap(params.voxel or voxel, max_range, params.rebuild, params.threads)
            length = max(float(np.median(np.linalg.norm(points, axis=1))), 1.0)
            decision = ScanDecision(frame.stamp, "kept", "first", 1.0, 0.0, 1.0, 0.0, 0.0)
        else:
            source = local.source(points)
            sensor, decision = _decide(local, source, sensor, length, params,
                                       stamp=frame.stamp)
        local.add(points, sensor)
        counts.seconds += time.perf_counter() - began
        counts.cpu_seconds += time.thread_time() - cpu
        _count(counts, decision)
        body = sensor @ sensor_body
        yield replace(frame, position=body[:3, 3].copy(),
                      quaternion=Rotation.from_matrix(body[:3, :3]).as_quat())
