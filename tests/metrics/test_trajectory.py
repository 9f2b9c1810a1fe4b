"""ATE / RPE (evo) against independent computations, and the cloud distance."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from alte.errors import MetricsError
from alte.metrics.trajectory import cloud_distance, rigid_alignment, trajectory_errors

N = 41


def _kabsch_ate(source: np.ndarray, target: np.ndarray) -> float:
    """RMSE after the best rigid motion (an independent Kabsch, no reflection)."""
    mu_s, mu_d = source.mean(axis=0), target.mean(axis=0)
    u, _, vt = np.linalg.svd((target - mu_d).T @ (source - mu_s))
    sign = np.sign(np.linalg.det(u @ vt))
    rotation = u @ np.diag([1.0, 1.0, sign]) @ vt
    moved = (source - mu_s) @ rotation.T + mu_d
    return float(np.sqrt(np.mean(np.sum((moved - target) ** 2, axis=1))))


def _line() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A 20 m path, 0.5 m a step, bending gently (an exactly straight one has no unique
    alignment)."""
    stamps = np.arange(N, dtype=np.int64) * 500_000_000
    x = np.linspace(0, 20, N)
    positions = np.column_stack([x, 0.001 * x**2, 0.0005 * x**2])
    return stamps, positions, np.tile([0.0, 0.0, 0.0, 1.0], (N, 1))


def test_a_rigidly_moved_trajectory_has_no_error() -> None:
    stamps, positions, quats = _line()
    turn = Rotation.from_euler("zyx", [40, -10, 5], degrees=True)
    moved = turn.apply(positions) + np.array([3.0, -2.0, 1.0])
    errors = trajectory_errors(stamps, moved, (turn * Rotation.from_quat(quats)).as_quat(),
                               positions, quats)
    assert errors.ate_m == pytest.approx(0.0, abs=1e-9)
    assert errors.rpe_trans_pct == pytest.approx(0.0, abs=1e-6)
    assert errors.rpe_rot_deg_m == pytest.approx(0.0, abs=1e-6)


def test_ate_matches_an_independent_kabsch() -> None:
    stamps, positions, quats = _line()
    rng = np.random.default_rng(0)
    noisy = positions + rng.normal(0, 0.05, positions.shape) + [0.0, 0.0, 0.5]
    errors = trajectory_errors(stamps, noisy, quats, positions, quats)
    assert errors.ate_m == pytest.approx(_kabsch_ate(noisy, positions), rel=1e-6)


def test_rpe_is_per_cent_and_degrees_per_metre() -> None:
    stamps, positions, quats = _line()   # 1 m segments are 2 steps
    stretched = positions * 1.02         # 2 % too long everywhere
    errors = trajectory_errors(stamps, stretched, quats, positions, quats)
    assert errors.rpe_trans_pct == pytest.approx(2.0, rel=1e-3)
    assert errors.rpe_rot_deg_m == pytest.approx(0.0, abs=1e-9)
    assert N - 4 <= errors.segments <= N - 2
    yawing = Rotation.from_euler("z", 0.3 * positions[:, :1], degrees=True).as_quat()
    turned = trajectory_errors(stamps, positions, yawing, positions, quats)
    assert turned.rpe_rot_deg_m == pytest.approx(0.3, rel=1e-3)   # 0.3 deg per metre


def test_short_and_straight_paths_and_bad_input() -> None:
    stamps, positions, quats = _line()
    straight = positions * [1.0, 0.0, 0.0]
    beside = straight + np.array([0.0, 0.2, 0.0])
    shifted = trajectory_errors(stamps, beside, quats, straight, quats)
    assert shifted.ate_m == pytest.approx(0.0, abs=1e-9)  # aligned at the first pose
    short = trajectory_errors(stamps[:3], positions[:3] * 0.1, quats[:3], positions[:3] * 0.1,
                              quats[:3])
    assert np.isnan(short.rpe_trans_pct) and short.segments == 0
    with pytest.raises(MetricsError, match="need >= 3 matched poses"):
        trajectory_errors(stamps[:2], positions[:2], quats[:2], positions[:2], quats[:2])


def test_cloud_distance_median_and_p90() -> None:
    reference = np.column_stack([np.arange(100.0), np.zeros(100), np.zeros(100)])
    cloud = reference + np.column_stack([np.zeros(100), np.zeros(100),
                                         np.linspace(0.0, 0.099, 100)])
    found = cloud_distance(cloud, reference)
    assert found.median_m == pytest.approx(np.median(np.linspace(0.0, 0.099, 100)))
    assert found.p90_m == pytest.approx(np.percentile(np.linspace(0.0, 0.099, 100), 90))


def test_rigid_alignment_undoes_a_rigid_motion_and_matches_kabsch() -> None:
    _, positions, _ = _line()
    turn = Rotation.from_euler("zyx", [40, -10, 5], degrees=True)
    moved = turn.apply(positions) + np.array([3.0, -2.0, 1.0])
    found = rigid_alignment(moved, positions)
    assert np.allclose(moved @ found[:3, :3].T + found[:3, 3], positions, atol=1e-9)
    noisy = positions + np.random.default_rng(1).normal(0, 0.05, positions.shape)
    fit = rigid_alignment(noisy, positions)
    placed = noisy @ fit[:3, :3].T + fit[:3, 3]
    rmse = float(np.sqrt(np.mean(np.sum((placed - positions) ** 2, axis=1))))
    assert rmse == pytest.approx(_kabsch_ate(noisy, positions), rel=1e-6)


def test_rigid_alignment_of_a_straight_path_and_bad_input() -> None:
    _, positions, _ = _line()
    straight = positions * [1.0, 0.0, 0.0]
    found = rigid_alignment(straight + np.array([0.0, 0.2, 0.0]), straight)
    assert np.allclose(found[:3, :3], np.eye(3)) and np.allclose(found[:3, 3], [0, -0.2, 0])
    with pytest.raises(MetricsError, match=r"rigid alignment needs matched positions"):
        rigid_alignment(positions[:3], positions[:4])


def _flat(n: int) -> np.ndarray:
    return np.tile([0.0, 0.0, 0.0, 1.0], (n, 1))


def test_a_known_ate_on_a_hand_made_circle() -> None:
    """Eight poses 45 degrees apart on a 10 m circle, each estimate 0.1 m above or below it,
    alternately: the errors have no mean and no correlation with the path, so the best
    rigid alignment is the identity and the ATE is exactly 0.1 m. The poses are 7.65 m
    apart, so no two are one 1 m segment apart: no RPE."""
    turn = np.radians(np.arange(8) * 45.0)
    reference = np.column_stack([10 * np.cos(turn), 10 * np.sin(turn), np.zeros(8)])
    estimate = reference + np.column_stack([np.zeros((8, 2)), 0.1 * (-1.0) ** np.arange(8)])
    got = trajectory_errors(np.arange(8) * 10**9, estimate, _flat(8), reference, _flat(8))
    assert got.ate_m == pytest.approx(0.1, abs=1e-12)
    assert np.isnan(got.rpe_trans_pct) and np.isnan(got.rpe_rot_deg_m)
    assert (got.delta_m, got.segments) == (1.0, 0)
    # integer input (a hand-typed trajectory) reads the same as floats
    moved = trajectory_errors(list(range(8)), (estimate * 10).round().astype(int),
                              _flat(8).astype(int), (reference * 10).round().astype(int),
                              _flat(8).astype(int))
    assert moved.ate_m == pytest.approx(_kabsch_ate((estimate * 10).round(),
                                                    (reference * 10).round()), rel=1e-9)


def test_rpe_over_two_metre_segments() -> None:
    stamps, positions, quats = _line()   # 0.5 m steps: a 2 m segment is 4 steps
    stretched = trajectory_errors(stamps, positions * 1.02, quats, positions, quats,
                                  delta_m=2.0)
    assert stretched.delta_m == 2.0
    assert stretched.rpe_trans_pct == pytest.approx(2.0, rel=1e-3)   # still 2 %
    assert N - 6 <= stretched.segments <= N - 4
    yawing = Rotation.from_euler("z", 0.3 * positions[:, :1], degrees=True).as_quat()
    turned = trajectory_errors(stamps, positions, yawing, positions, quats, delta_m=2.0)
    assert turned.rpe_rot_deg_m == pytest.approx(0.3, rel=1e-3)   # 0.6 deg per 2 m


def test_rpe_needs_one_and_a_half_segments_of_path() -> None:
    """RPE is measured from 1.5 segments of reference path on (the boundary included),
    wherever the path lies."""
    far = np.array([100.0, 50.0, 10.0])
    stamps = np.arange(13, dtype=np.int64) * 10**8

    def path(step: float) -> np.ndarray:
        return far + np.column_stack([np.arange(13) * step, 1e-3 * np.arange(13) ** 2,
                                      np.zeros(13)])

    short = path(0.08)        # about 0.96 m: short of 1.5 segments
    got = trajectory_errors(stamps, short + np.array([0.0, 0.0, 0.02]), _flat(13), short,
                            _flat(13))
    assert np.isnan(got.rpe_trans_pct) and got.segments == 0
    assert got.ate_m == pytest.approx(0.0, abs=1e-9) and got.delta_m == 1.0
    exact = far + np.column_stack([np.arange(13) * 0.125, np.zeros((13, 2))])  # 1.5 m exactly
    longer = trajectory_errors(stamps, exact, _flat(13), exact, _flat(13))
    assert longer.segments > 0 and longer.rpe_trans_pct == pytest.approx(0.0, abs=1e-6)
    two = far + np.column_stack([np.arange(13) * 0.2, 1e-3 * np.arange(13) ** 2,
                                 np.zeros(13)])   # 2.4 m: under 1.5 segments of 2 m
    halved = trajectory_errors(stamps, two, _flat(13), two, _flat(13), delta_m=2.0)
    assert np.isnan(halved.rpe_rot_deg_m) and halved.segments == 0
