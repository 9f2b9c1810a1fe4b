"""Refinement of recorded poses that moves them only on evidence.

Each scan is aligned point-to-plane (Gauss-Newton,
:func:`~alte.registration.refalign.align`) to a map of the scans before it, placed with
their refined poses (:class:`~alte.registration.refmap.DenseMap`, updated
incrementally), starting from its recorded pose. The alignment moves the pose only
along the directions the scan constrains: a direction whose Gauss-Newton Hessian
eigenvalue (rotation scaled by the scan's median range, so both blocks are in metres)
is below ``min_constraint`` times the largest keeps its recorded value (a scan in a
corridor is corrected across it, not along it); the scan's decision counts those
directions in ``free``. The correction
replaces the recorded pose only when all of these hold, else the recorded pose is kept
and the scan counted as kept with the first reason that failed:

``weak``
    fewer than ``min_fitness`` of the scan's points have a map point within reach;
``above_bound``
    the correction exceeds ``max_correction`` m or ``max_correction_deg``;
``no_gain``
    the correction removes less than ``min_gain`` of the scan's point-to-plane cost at
    the recorded pose, truncated at three times its own residual noise
    (:func:`~alte.registration.refalign.evidence`);
``unobserved``
    the scan sees the corrected direction with less than ``min_information`` (the
    Hessian along it per point: a slide over flat ground, a turn about a pole).

This corrects desynchronised poses (thesis fig. 4.34) and leaves good ones alone. The
two evidence thresholds were chosen on the real ``balm_seq`` and ``balm_seq2``
recordings, whose reference poses no alignment should move, and the simulated
``exp_nav_2``, whose late poses it should (docs/results/poses.md, "Cross-validation").
Every scan has a :class:`ScanDecision` in ``PoseCounts.scans``.
"""

from __future__ import annotations

import time
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from alte.registration.backends import scene_scale
from alte.registration.refalign import align, evidence
from alte.registration.refmap import DenseMap
from alte.registration.settings import pose_matrix
from alte.types import Frame, Mount

if TYPE_CHECKING:
    from alte.registration.settings import OdometrySettings, PoseCounts

__all__ = ["REASONS", "ScanDecision", "refine_frames"]

#: Why a scan keeps its recorded pose (module docstring), in the order they are tested.
REASONS = ("first", "weak", "above_bound", "no_gain", "unobserved")
#: Reasons that confirm the recorded pose: the scan joins the map's cells as recorded.
CONFIRMED = ("first", "no_gain", "unobserved")


@dataclass(frozen=True)
class ScanDecision:
    """What refinement did to one scan: ``corrected`` or ``kept`` and why; the alignment's
    inlier fraction, cost gain (1 - aligned / recorded cost), information along the
    correction, the scan's residual noise (m), constraint ratio (smallest over largest
    scaled Hessian eigenvalue), directions left at the recorded pose and the size of the
    correction it proposed (applied only when ``corrected``)."""

    stamp: int
    decision: str
    reason: str
    fitness: float
    gain: float
    information: float
    noise: float
    constraint: float
    free: int
    metres: float
    degrees: float

    def as_dict(self) -> dict[str, object]:
        """JSON-ready."""
        return {k: (round(v, 6) if isinstance(v, float) else v) for k, v in vars(self).items()}


def _constraint(hessian: NDArray[np.float64], length: float) -> float:
    """Smallest over largest eigenvalue of the Hessian (rotation first) with rotation
    scaled to metres at ``length``."""
    scale = np.diag([1.0 / length] * 3 + [1.0] * 3)
    values = np.linalg.eigvalsh(scale @ np.asarray(hessian) @ scale)
    return float(max(values[0], 0.0) / values[-1]) if values[-1] > 0 else 0.0


def _correction(guess: NDArray[np.float64], aligned: NDArray[np.float64]) -> tuple[float, float]:
    """Size of ``guess -> aligned``: metres and degrees."""
    delta = np.linalg.inv(guess) @ aligned
    angle = Rotation.from_matrix(delta[:3, :3]).magnitude()
    return float(np.linalg.norm(delta[:3, 3])), float(np.degrees(angle))


def _decide(local: DenseMap, points: NDArray[np.float64], guess: NDArray[np.float64],
            length: float, params: OdometrySettings, *, stamp: int,
            ) -> tuple[NDArray[np.float64], ScanDecision]:
    """The pose to use for the scan and why (module docstring)."""
    found = align(local, points, guess, length=length, ratio=params.min_constraint)
    worth = evidence(local, points, guess, found, length)
    metres, degrees = _correction(guess, found.pose)
    checks = (("weak", worth.fitness < params.min_fitness),
              ("above_bound", metres > params.max_correction
               or degrees > params.max_correction_deg),
              ("no_gain", worth.gain < params.min_gain),
              ("unobserved", worth.information < params.min_information))
    reason = next((name for name, failed in checks if failed), "")
    decision = ScanDecision(stamp, "kept" if reason else "corrected", reason, worth.fitness,
                            worth.gain, worth.information, worth.noise,
                            _constraint(found.hessian, length), found.free, metres, degrees)
    return (guess if reason else found.pose), decision


def _count(counts: PoseCounts, decision: ScanDecision) -> None:
    counts.scans.append(decision.as_dict())
    if decision.decision == "kept":
        counts.kept[decision.reason] = counts.kept.get(decision.reason, 0) + 1
        return
    counts.corrected += 1
    counts.max_correction_m = max(counts.max_correction_m, decision.metres)
    counts.max_correction_deg = max(counts.max_correction_deg, decision.degrees)


def refine_frames(frames: Iterable[Frame], mount: Mount, *, counts: PoseCounts,
                  params: OdometrySettings) -> Iterator[Frame]:
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
            decision = ScanDecision(frame.stamp, "kept", "first", 1.0, 0.0, 0.0, 0.0, 1.0, 0,
                                    0.0, 0.0)
        else:
            sensor, decision = _decide(local, local.source(points), sensor, length, params,
                                       stamp=frame.stamp)
        local.add(points, sensor, confirmed=decision.reason in CONFIRMED)
        counts.seconds += time.perf_counter() - began
        counts.cpu_seconds += time.thread_time() - cpu
        _count(counts, decision)
        body = sensor @ sensor_body
        yield replace(frame, position=body[:3, 3].copy(),
                      quaternion=Rotation.from_matrix(body[:3, :3]).as_quat())
