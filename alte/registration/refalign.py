"""A scan aligned to the refinement's map, and the evidence that its correction is real.

:func:`align` is point-to-plane Gauss-Newton (correspondences from the map's k-d tree,
normals from the map, :class:`~alte.registration.refmap.DenseMap`) that moves a pose
only along the directions the scan constrains, first its rotation alone, then all six
directions. small_gicp's own alignment needs the target's normals in its point cloud,
which it can only estimate for the whole cloud. (A Cauchy-reweighted alignment was
tried and not kept: on the simulated ``exp_nav_2`` it leaves more late poses
uncorrected, 35 mm from the true mesh against 31.7 mm; docs/design-notes/poses.md.)

:func:`evidence` measures what a correction is worth, on the scan's own terms:

``gain``
    how much of the scan's residual cost at the recorded pose the correction removes,
    the cost truncated at :data:`TRUNCATE` times the scan's residual noise there (a
    significance test of the cost reduction against that noise: points between
    surfaces weigh no more than a few sigmas, so a correction that only moves a few of
    them onto a surface gains little);
``information``
    how strongly the scan's points see the corrected direction: the Hessian along it per
    matched point (1: every residual moves as much as the pose; 0: none). A correction
    along a direction the scan barely sees (a slide over flat ground) is what noise and
    a map of sparse rings produce.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

if TYPE_CHECKING:
    from alte.registration.refmap import DenseMap

__all__ = ["MAX_ITERATIONS", "TRUNCATE", "Alignment", "Evidence", "align",
           "evidence", "noise"]

#: Truncation of the cost :func:`evidence` compares, in residual-noise sigmas.
TRUNCATE = 3.0
#: Least residual noise (m): a scan whose residuals are all near zero fits already.
NOISE_FLOOR = 1e-3
#: Gauss-Newton steps at most; it stops earlier once a step moves less than
#: :data:`_CONVERGED` (radians, metres).
MAX_ITERATIONS = 30
_CONVERGED = (np.radians(0.1), 1e-3)


def noise(residuals: NDArray[np.float64]) -> float:
    """Robust standard deviation of point-to-plane residuals (m): 1.4826 times their
    median absolute value, at least :data:`NOISE_FLOOR`."""
    if not len(residuals):
        return NOISE_FLOOR
    return max(1.4826 * float(np.median(np.abs(residuals))), NOISE_FLOOR)


@dataclass(frozen=True)
class Alignment:
    """Where the scan was aligned to (sensor pose, 4x4), the Gauss-Newton Hessian at that
    pose (6x6, rotation first, rotation in radians), the number of matched points it was
    built from and how many of its six directions were left at the guess (too weakly
    constrained to move)."""

    pose: NDArray[np.float64]
    hessian: NDArray[np.float64]
    weight: float
    free: int


def _exp(step: NDArray[np.float64]) -> NDArray[np.float64]:
    """4x4 transform of a small (rotation vector, translation) step."""
    out = np.eye(4)
    out[:3, :3] = Rotation.from_rotvec(step[:3]).as_matrix()
    out[:3, 3] = step[3:]
    return out


def _scaling(length: float, size: int = 6) -> NDArray[np.float64]:
    """Rotation scaled to metres at ``length`` (its block first)."""
    return np.diag([1.0 / length] * 3 + [1.0] * 3)[:size, :size]


def _step(hessian: NDArray[np.float64], gradient: NDArray[np.float64], length: float,
          ratio: float, turn_only: bool) -> tuple[NDArray[np.float64], int]:
    """Gauss-Newton step restricted to the directions whose Hessian eigenvalue (rotation
    scaled to metres at ``length``) is at least ``ratio`` times the largest; the others
    stay where they are (solution remapping, Zhang, Kaess and Singh, ICRA 2016).
    ``turn_only``: the rotation block alone (position held)."""
    size = 3 if turn_only else 6
    scale = _scaling(length, size)
    values, vectors = np.linalg.eigh(scale @ hessian[:size, :size] @ scale)
    good = values >= max(ratio * values[-1], 1e-12)
    basis = vectors[:, good]
    step = np.zeros(6)
    step[:size] = scale @ (-basis @ ((basis.T @ (scale @ gradient[:size])) / values[good]))
    return step, int((~good).sum())


def _solve(local: DenseMap, points: NDArray[np.float64], pose: NDArray[np.float64], *,
           length: float, ratio: float, turn_only: bool) -> Alignment:
    """Gauss-Newton iterations from ``pose`` (:func:`align`)."""
    hessian, weight, free = np.zeros((6, 6)), 0.0, 0
    for _ in range(MAX_ITERATIONS):
        rot = pose[:3, :3]
        inlier, index, residual = local.matches(points @ rot.T + pose[:3, 3])
        if not inlier.any():
            break
        turned = local.normals[index[inlier]] @ rot
        jacobian = np.hstack([np.cross(points[inlier], turned), turned])
        hessian, weight = jacobian.T @ jacobian, float(inlier.sum())
        step, free = _step(hessian, jacobian.T @ residual[inlier], length, ratio, turn_only)
        pose = pose @ _exp(step)
        if np.linalg.norm(step[:3]) < _CONVERGED[0] and np.linalg.norm(step[3:]) < _CONVERGED[1]:
            break
    return Alignment(pose, hessian, weight, free)


def align(local: DenseMap, points: NDArray[np.float64], guess: NDArray[np.float64], *,
          length: float, ratio: float) -> Alignment:
    """Point-to-plane Gauss-Newton of sensor-frame ``points`` onto ``local`` from ``guess``
    (poses compose on the right, rotation first), moving only along the directions
    constrained at least ``ratio`` (:func:`_step`): first the rotation about the sensor
    alone, then all six directions. A late pose is mostly turned (the vehicle swings
    faster than it moves), and a turn left to the full alignment is partly taken up by
    a shift that lands it in a wrong minimum."""
    turned = _solve(local, points, guess, length=length, ratio=ratio, turn_only=True)
    return _solve(local, points, turned.pose, length=length, ratio=ratio, turn_only=False)


@dataclass(frozen=True)
class Evidence:
    """What a correction is worth (module docstring): the inlier fraction at the aligned
    pose, the truncated cost gain, the information along the corrected direction and the
    scan's residual noise at the recorded pose (m)."""

    fitness: float
    gain: float
    information: float
    noise: float


def _information(found: Alignment, guess: NDArray[np.float64], length: float) -> float:
    """Hessian along the correction ``guess -> found.pose`` (rotation in metres at
    ``length``) per unit of squared correction and per matched point."""
    delta = np.linalg.inv(guess) @ found.pose
    step = np.concatenate([Rotation.from_matrix(delta[:3, :3]).as_rotvec(), delta[:3, 3]])
    metres = np.linalg.solve(_scaling(length), step)
    size = float(metres @ metres)
    if size == 0.0 or found.weight <= 0.0:
        return 0.0
    return float(step @ found.hessian @ step) / (size * found.weight)


def evidence(local: DenseMap, points: NDArray[np.float64], guess: NDArray[np.float64],
             found: Alignment, length: float) -> Evidence:
    """The evidence for moving sensor-frame ``points`` from ``guess`` to ``found``."""
    inlier, _, residual = local.matches(points @ guess[:3, :3].T + guess[:3, 3])
    sigma = noise(residual[inlier])
    cap = TRUNCATE * sigma
    fitness, after = local.cost(points, found.pose, cap)
    _, before = local.cost(points, guess, cap)
    gain = 1.0 - after / before if before > 0 else 0.0
    return Evidence(fitness, gain, _information(found, guess, length), sigma)
