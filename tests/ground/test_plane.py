"""Tests for alte.ground: MSAC plane fit, Open3D comparison, height above ground."""

from __future__ import annotations

import numpy as np
import pytest

from alte.errors import GroundError, ParameterError
from alte.ground.plane import (
    PlaneFit,
    fit_plane_msac,
    fit_plane_open3d,
    height_above,
    obstacle_mask,
)
from alte.io import read_frames
from alte.io.bags.bag import ReadSettings
from alte.paths import realdata_dir
from alte.registration import grid_average

NORMAL = np.array([0.1, -0.2, 1.0]) / np.linalg.norm([0.1, -0.2, 1.0])
D = -2.0


def plane_cloud(n: int = 3000, outliers: float = 0.4, noise: float = 0.02, seed: int = 1):
    """Points on NORMAL.p + D = 0 with Gaussian noise plus uniform outliers; inlier mask."""
    rng = np.random.default_rng(seed)
    xy = rng.uniform(-20, 20, (n, 2))
    z = (-D - xy @ NORMAL[:2]) / NORMAL[2]
    pts = np.c_[xy, z] + rng.normal(0, noise, (n, 3))
    out = rng.random(n) < outliers
    pts[out] = rng.uniform([-20, -20, 0], [20, 20, 12], (int(out.sum()), 3))
    return pts, ~out


def angle_deg(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.degrees(np.arccos(np.clip(abs(a @ b), -1, 1))))


def test_msac_recovers_plane_with_40_percent_outliers():
    pts, truth = plane_cloud()
    fit = fit_plane_msac(pts, threshold=0.1)
    assert angle_deg(fit.normal, NORMAL) < 0.5
    assert fit.normal[2] > 0
    assert fit.d == pytest.approx(D, abs=0.02)
    assert np.linalg.norm(fit.normal) == pytest.approx(1.0)
    # every true inlier within 5 sigma is found; few outliers sneak in near the plane
    assert fit.inliers[truth].mean() > 0.99
    assert fit.inliers[~truth].mean() < 0.05
    dist = np.abs(pts @ fit.normal + fit.d)
    assert fit.cost == pytest.approx(np.minimum(dist**2, 0.01).sum())


def test_msac_is_deterministic_per_seed():
    pts, _ = plane_cloud(outliers=0.6, seed=2)
    a = fit_plane_msac(pts, seed=7)
    b = fit_plane_msac(pts, seed=7)
    np.testing.assert_array_equal(a.normal, b.normal)
    np.testing.assert_array_equal(a.inliers, b.inliers)
    assert a.d == b.d


def test_msac_adapts_iterations_to_inlier_ratio():
    clean, _ = plane_cloud(outliers=0.0, seed=3)
    dirty, _ = plane_cloud(outliers=0.8, seed=3)
    few = fit_plane_msac(clean, max_iterations=5000)
    many = fit_plane_msac(dirty, max_iterations=5000)
    assert few.iterations <= 256  # one batch is enough for clean data
    assert many.iterations > 256  # 20 % inliers: ~570 draws for 99 %
    assert angle_deg(many.normal, NORMAL) < 0.5


def test_msac_agrees_with_open3d():
    pts, _ = plane_cloud(n=1500, seed=4)
    ours = fit_plane_msac(pts, threshold=0.1)
    theirs = fit_plane_open3d(pts, threshold=0.1)
    assert angle_deg(ours.normal, theirs.normal) < 0.5
    assert ours.d == pytest.approx(theirs.d, abs=0.05)
    assert (ours.inliers != theirs.inliers).mean() < 0.01
    assert ours.cost <= theirs.cost * 1.01


def test_msac_reference_normal_picks_the_ground_not_a_wall():
    rng = np.random.default_rng(5)
    ground = np.c_[rng.uniform(0, 10, (400, 2)), np.zeros(400)]
    wall = np.c_[np.full(1200, 5.0), rng.uniform(0, 10, 1200), rng.uniform(0, 10, 1200)]
    pts = np.vstack([ground, wall])
    assert abs(fit_plane_msac(pts).normal[0]) > 0.99  # the wall dominates
    fit = fit_plane_msac(pts, reference_normal=(0, 0, 1), max_angle_deg=10)
    assert angle_deg(fit.normal, np.array([0, 0, 1.0])) < 0.1  # wall foot points tilt it a bit
    assert fit.inliers[:400].all()


def test_height_above_and_obstacle_mask():
    plane = PlaneFit(normal=np.array([0, 0, 1.0]), d=-1.0, inliers=np.zeros(0, bool), cost=0.0)
    pts = np.array([[0, 0, 1.0], [5, 5, 1.5], [0, 0, 0.5], [1, 1, 1.31]])
    np.testing.assert_allclose(height_above(pts, plane), [0, 0.5, -0.5, 0.31])
    np.testing.assert_array_equal(obstacle_mask(pts, plane, 0.3), [False, True, False, True])
    with pytest.raises(ParameterError, match="height"):
        obstacle_mask(pts, plane, np.nan)


def test_degenerate_inputs_raise():
    with pytest.raises(GroundError, match="at least 3 points, got 2"):
        fit_plane_msac(np.zeros((2, 3)))
    line = np.c_[np.arange(50.0), 2 * np.arange(50.0), np.zeros(50)]
    with pytest.raises(GroundError, match="no valid plane"):
        fit_plane_msac(line, max_iterations=50)
    with pytest.raises(GroundError, match="no valid plane"):
        fit_plane_msac(np.ones((10, 3)), max_iterations=50)
    wall = np.c_[np.zeros(20), np.random.default_rng(0).uniform(0, 1, (20, 2))]
    with pytest.raises(GroundError, match="max_angle_deg"):
        fit_plane_msac(wall, reference_normal=(0, 0, 1), max_angle_deg=5)


@pytest.mark.parametrize(("kwargs", "match"), [
    ({"threshold": 0.0}, "threshold"),
    ({"threshold": np.nan}, "threshold"),
    ({"max_iterations": 0}, "max_iterations"),
    ({"confidence": 1.0}, "confidence"),
    ({"reference_normal": (0, 0, 1)}, "together"),
    ({"reference_normal": (0, 0), "max_angle_deg": 5}, "reference_normal"),
    ({"reference_normal": (0, 0, 1), "max_angle_deg": 95}, "max_angle_deg"),
])
def test_bad_parameters_raise(kwargs, match):
    with pytest.raises(ParameterError, match=match):
        fit_plane_msac(np.eye(3), **kwargs)


@pytest.mark.parametrize(("points", "match"), [
    (np.zeros((5, 2)), "shape"),
    (np.array([[0, 0, np.nan]] * 3), "NaN"),
])
def test_bad_points_raise(points, match):
    with pytest.raises(ParameterError, match=match):
        fit_plane_msac(points)
    with pytest.raises(ParameterError, match=match):
        fit_plane_open3d(points)


def test_open3d_errors():
    with pytest.raises(ParameterError, match="threshold"):
        fit_plane_open3d(np.eye(3), threshold=-1)
    with pytest.raises(GroundError, match="at least 3"):
        fit_plane_open3d(np.eye(3)[:2])


REALDATA = realdata_dir()


@pytest.mark.realdata
def test_msac_on_real_luminar_scans_matches_open3d():
    bag = REALDATA / "ros1_bag" / "test.bag"
    if not bag.exists():
        pytest.skip(f"{bag} absent")
    frames = read_frames(bag, ReadSettings(pose_topic="", allow_no_pose=True))
    pts = grid_average(np.vstack([f.points for f in frames.frames]), 0.5)[::4]
    ours = fit_plane_msac(pts, threshold=0.15)
    theirs = fit_plane_open3d(pts, threshold=0.15)
    assert angle_deg(ours.normal, np.array([0, 0, 1.0])) < 5  # a road seen from a truck
    assert angle_deg(ours.normal, theirs.normal) < 1.5
    assert ours.cost <= theirs.cost * 1.02
