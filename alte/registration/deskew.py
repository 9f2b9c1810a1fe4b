"""Motion compensation (deskew): a swept scan re-expressed as if taken at its stamp.

A spinning LiDAR takes each point at its own instant while the vehicle moves (at 5 m/s
a 100 ms sweep smears by 0.5 m). When the cloud carries per-point time, each point is
moved with the sensor's motion from its instant to the scan stamp,
``p' = T_S(stamp)^-1 T_S(stamp + t_i) p_i`` (``T_S`` the sensor pose: body pose x mount),
so registering it with the pose at the stamp (eq. 2.2) is exact. The motion comes from:

* :func:`deskew_frames`: a pose track (the bag's recorded poses, interpolated: linear
  position, slerp attitude), for ``--poses recorded`` / ``refine``;
* :func:`deskew_constant_velocity`: a constant body twist over the sweep, for odometry
  backends without their own deskew (the motion between their last two poses).

Times are grouped on a 0.1 ms grid (a 10 Hz sweep has at most 1,000 poses to look up;
at 10 m/s the grouping moves a point by 1 mm), so a 70,000-point scan needs ~1,000
pose interpolations and one batched matrix product, never a loop over points.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from alte.io.poses.pose import PoseTrack
from alte.types import Counts, Frame, Mount

__all__ = ["DESKEW_STEP_S", "DeskewCounts", "deskew_constant_velocity", "deskew_frames",
           "deskew_points"]

#: Time grid on which per-point times are grouped (s).
DESKEW_STEP_S = 1e-4


@dataclass
class DeskewCounts(Counts):
    """Scans deskewed, scans without per-point time, and points whose instant lies
    outside the pose track (moved with the nearest pose there: no extrapolation)."""

    deskewed: int = 0
    no_time: int = 0
    points_clamped: int = 0


def _groups(times: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.intp]]:
    """Grid times (G,) in seconds and each point's group index (N,)."""
    keys = np.round(np.asarray(times, dtype=np.float64) / DESKEW_STEP_S).astype(np.int64)
    unique, index = np.unique(keys, return_inverse=True)
    return np.asarray(unique * DESKEW_STEP_S, dtype=np.float64), index.reshape(-1)


def deskew_points(points: NDArray[np.float64], times: NDArray[np.float64],
                  rotations: Rotation[tuple[int]], translations: NDArray[np.float64],
                  index: NDArray[np.intp]) -> NDArray[np.float64]:
    """Apply the per-group motion (rotation ``rotations[g]``, translation ``translations[g]``
    taking the sensor at time g to the sensor at the stamp) to each point of group
    ``index[i]``: ``R_g p + t_g``. ``times`` is unused beyond its length check."""
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    if len(times) != len(pts) or len(index) != len(pts):
        raise ValueError(f"deskew: {len(pts)} points but {len(times)} times")
    mats = rotations.as_matrix().reshape(-1, 3, 3)
    moved: NDArray[np.float64] = np.einsum("nij,nj->ni", mats[index], pts) + translations[index]
    return moved


def _sensor_poses(track: PoseTrack, stamps: NDArray[np.int64], mount: Mount,
                  max_gap_s: float,
                  ) -> tuple[Rotation[tuple[int]], NDArray[np.float64], NDArray[np.bool_]]:
    """Sensor rotations and positions at ``stamps`` (ns) from the body track; the mask of
    stamps the track could not give (outside or in a gap: nearest valid pose used)."""
    samples = track.interpolate(stamps, max_gap_s)
    valid = samples.valid
    pos, quat = samples.positions, samples.quaternions
    if not valid.any():
        return Rotation.identity(len(stamps)), np.zeros((len(stamps), 3)), ~valid
    if not valid.all():
        good = np.flatnonzero(valid)
        nearest = good[np.abs(good[None, :] - np.arange(len(stamps))[:, None]).argmin(axis=1)]
        pos, quat = pos[nearest], quat[nearest]
    body = Rotation.from_quat(quat)
    return body * mount.rotation, pos + body.apply(mount.translation), ~valid


def deskew_frames(frames: Iterable[Frame], track: PoseTrack, mount: Mount, *,
                  counts: DeskewCounts, max_gap_s: float = 0.5) -> Iterator[Frame]:
    """``frames`` with timed points moved to their scan stamp along ``track`` (the body
    poses; module docstring). Frames without per-point time pass unchanged (counted);
    deskewed frames come out with ``times=None``."""
    for frame in frames:
        if frame.times is None or len(frame.times) == 0:
            counts.no_time += frame.times is None
            yield frame
            continue
        grid, index = _groups(frame.times)
        stamps = frame.stamp + np.round(np.r_[0.0, grid] * 1e9).astype(np.int64)
        rot, pos, clamped = _sensor_poses(track, stamps, mount, max_gap_s)
        if clamped[0] or clamped[1:].all():
            counts.no_time += 1  # no pose at the stamp, or none in the sweep: leave it
            yield replace(frame, times=None)
            continue
        to_stamp = rot[0].inv()
        rel = to_stamp * rot[1:]
        shift = to_stamp.apply(pos[1:] - pos[0])
        counts.points_clamped += int(clamped[1:][index].sum())
        counts.deskewed += 1
        moved = deskew_points(frame.points, frame.times, rel, shift, index)
        yield replace(frame, points=moved, times=None)


def deskew_constant_velocity(points: NDArray[np.float64], times: NDArray[np.float64],
                             motion: NDArray[np.float64], period_s: float) -> NDArray[np.float64]:
    """Points moved to the stamp under a constant sensor twist: ``motion`` (4x4) is the
    sensor's displacement over ``period_s`` seconds (previous scan -> this one)."""
    grid, index = _groups(times)
    twist = Rotation.from_matrix(motion[:3, :3]).as_rotvec() / period_s
    velocity = motion[:3, 3] / period_s
    rel = Rotation.from_rotvec(grid[:, None] * twist[None, :])
    shift = grid[:, None] * velocity[None, :]
    return deskew_points(points, times, rel, shift, index)
