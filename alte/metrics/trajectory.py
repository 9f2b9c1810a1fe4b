"""How far estimated poses are from reference poses, as ``evo`` reports it.

* ATE: RMSE of the position error after the rigid (SE(3), no scale) Umeyama alignment
  of the estimate onto the reference (``evo_ape --align``); on a straight path, where
  that alignment is undefined, after aligning the first poses (``--align_origin``).
* RPE over segments of ``delta_m`` metres of the reference path (``evo_rpe --delta 1
  --delta_unit m --all_pairs``): the mean translation error as a percentage of the
  segment length and the mean rotation error in degrees per metre. RPE needs no
  alignment (it compares relative motions).
* Cloud distance: each point of a registered cloud to its nearest point of the cloud
  registered with the reference poses (median and 90th percentile).
* :func:`rigid_alignment`: the SE(3) transform that ATE applies (Umeyama, no scale), to
  place an odometry cloud in the reference frame the same way.

The poses must already be matched one to one (the same stamps): the caller samples the
reference at the estimate's stamps.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from alte.errors import MetricsError
from alte.metrics.hausdorff import directed_distances
from alte.metrics.nearest import NearestIndex

__all__ = ["CloudDistance", "TrajectoryErrors", "cloud_distance", "rigid_alignment",
           "trajectory_errors"]


@dataclass(frozen=True)
class TrajectoryErrors:
    """ATE (m), RPE translation (% of ``delta_m``) and rotation (deg/m); NaN RPE when the
    reference path is shorter than one segment or no two scans are one segment apart."""

    ate_m: float
    rpe_trans_pct: float
    rpe_rot_deg_m: float
    delta_m: float
    segments: int


@dataclass(frozen=True)
class CloudDistance:
    """Median and 90th percentile distance (m) of a cloud to the reference cloud."""

    median_m: float
    p90_m: float


def _trajectory(stamps: NDArray[np.int64], positions: NDArray[np.float64],
                quaternions: NDArray[np.float64]) -> object:
    from evo.core.trajectory import PoseTrajectory3D

    xyzw = np.asarray(quaternions, dtype=np.float64)
    return PoseTrajectory3D(np.asarray(positions, dtype=np.float64), xyzw[:, [3, 0, 1, 2]],
                            np.asarray(stamps, dtype=np.int64) / 1e9)


def _rpe(reference: object, estimate: object, relation: object,
         delta_m: float) -> tuple[float, int]:
    """Mean RPE over every pair of poses ``delta_m`` apart along the reference, and the
    number of pairs."""
    from evo.core import metrics
    from evo.core.units import Unit

    rpe = metrics.RPE(relation, delta=delta_m, delta_unit=Unit.meters, all_pairs=True)
    rpe.process_data((reference, estimate))
    return float(rpe.get_statistic(metrics.StatisticsType.mean)), len(rpe.error)


def trajectory_errors(stamps: NDArray[np.int64], positions: NDArray[np.float64],
                      quaternions: NDArray[np.float64], reference_positions: NDArray[np.float64],
                      reference_quaternions: NDArray[np.float64],
                      *, delta_m: float = 1.0) -> TrajectoryErrors:
    """ATE and RPE of matched poses (module docstring); quaternions are x, y, z, w."""
    import copy

    from evo.core import metrics
    from evo.core.filters import FilterException
    from evo.core.geometry import GeometryException
    from evo.core.metrics import PoseRelation

    if len(stamps) < 3 or np.shape(positions) != np.shape(reference_positions):
        raise MetricsError(f"trajectory errors need >= 3 matched poses, got {len(stamps)} "
                           f"estimated and {len(reference_positions)} reference")
    reference = _trajectory(stamps, reference_positions, reference_quaternions)
    estimate = _trajectory(stamps, positions, quaternions)
    aligned = copy.deepcopy(estimate)
    try:
        aligned.align(reference, correct_scale=False)  # type: ignore[attr-defined]
    except GeometryException:  # a straight path: the turn about it is unobservable
        aligned.align_origin(reference)  # type: ignore[attr-defined]
    ape = metrics.APE(PoseRelation.translation_part)
    ape.process_data((reference, aligned))
    ate = float(ape.get_statistic(metrics.StatisticsType.rmse))
    steps = np.linalg.norm(np.diff(np.asarray(reference_positions), axis=0), axis=1)
    if steps.sum() < 1.5 * delta_m:
        return TrajectoryErrors(ate, float("nan"), float("nan"), delta_m, 0)
    try:
        trans, pairs = _rpe(reference, estimate, PoseRelation.translation_part, delta_m)
        rot, _ = _rpe(reference, estimate, PoseRelation.rotation_angle_deg, delta_m)
    except FilterException:  # scans further apart than a segment: no pair delta_m apart
        return TrajectoryErrors(ate, float("nan"), float("nan"), delta_m, 0)
    return TrajectoryErrors(ate, 100.0 * trans / delta_m, rot / delta_m, delta_m, pairs)


def cloud_distance(cloud: NDArray[np.float64], reference: NDArray[np.float64] | NearestIndex,
                   ) -> CloudDistance:
    """Median and p90 distance of every ``cloud`` point to its nearest ``reference`` point
    (``reference``: the points, or their :func:`~alte.metrics.hausdorff.target_index`)."""
    distances = directed_distances(cloud, reference)
    median, p90 = np.percentile(distances, [50, 90])
    return CloudDistance(float(median), float(p90))


def rigid_alignment(positions: NDArray[np.float64], reference_positions: NDArray[np.float64],
                    ) -> NDArray[np.float64]:
    """4x4 transform taking ``positions`` onto ``reference_positions`` in the least-squares
    sense (Umeyama, rotation and translation, no scale: what ATE aligns with); on a
    straight or single-point path, where the turn about it is unobservable, the shift of
    the first position alone."""
    from evo.core.geometry import GeometryException, umeyama_alignment

    mine = np.asarray(positions, dtype=np.float64)
    theirs = np.asarray(reference_positions, dtype=np.float64)
    if mine.shape != theirs.shape or mine.ndim != 2 or mine.shape[1] != 3 or not len(mine):
        raise MetricsError(f"rigid alignment needs matched positions (N x 3), got "
                           f"{mine.shape} and {theirs.shape}")
    out = np.eye(4)
    try:
        turn, shift, _ = umeyama_alignment(mine.T, theirs.T, False)
    except GeometryException:
        out[:3, 3] = theirs[0] - mine[0]
        return out
    out[:3, :3], out[:3, 3] = turn, shift
    return out
