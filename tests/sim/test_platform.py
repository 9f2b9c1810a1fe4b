"""Platforms: quadrotor and cart trajectories, motion-capture pose stream."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from alte.lab.plot.scene import attitude_deg
from alte.sim.platform import Cart, Quadrotor, Trajectory, mocap_stream

SQUARE = ((0.0, 0.0), (40.0, 0.0), (40.0, 30.0), (0.0, 30.0))


def test_quadrotor_flies_at_constant_altitude_with_yaw_along_the_path():
    traj = Trajectory(Quadrotor(SQUARE, altitude=12.0), duration=60.0)
    t = np.linspace(0.0, 60.0, 601)
    pos, rot = traj.pose(t)
    assert np.allclose(pos[:, 2], 12.0)
    assert np.allclose(pos[0, :2], SQUARE[0], atol=1e-6)
    assert np.allclose(pos[-1, :2], SQUARE[-1], atol=1e-6)
    vel = np.gradient(pos[:, :2], t, axis=0)
    moving = np.linalg.norm(vel, axis=1) > 0.5
    forward = rot.apply([1.0, 0.0, 0.0])[:, :2]
    cos = np.einsum("ij,ij->i", forward, vel) / np.linalg.norm(forward, axis=1) / np.linalg.norm(
        vel, axis=1)
    assert np.all(cos[moving] > 0.99)
    tilt = np.degrees(np.arccos(rot.apply([0, 0, 1.0])[:, 2]))
    assert tilt.max() < 15.0  # tilts only to accelerate


def test_cruise_speed_is_constant_and_covers_the_path():
    traj = Trajectory(Quadrotor(SQUARE, altitude=5.0, ramp_s=4.0), duration=50.0)
    t = np.linspace(10.0, 40.0, 301)
    speed = np.linalg.norm(np.gradient(traj.xy(t), t, axis=0), axis=1)
    assert np.allclose(speed, traj.speed, rtol=0.01)
    assert traj.speed == pytest.approx(traj.length / 46.0)


def test_cart_keeps_tripod_height_and_small_wobble():
    traj = Trajectory(Cart(SQUARE, wobble_deg=1.0), duration=100.0)
    pos, rot = traj.pose(np.linspace(0, 100, 1001))
    assert np.allclose(pos[:, 2], 1.8, atol=0.005)
    roll_pitch = rot.as_euler("ZYX", degrees=True)[:, 1:]
    assert np.abs(roll_pitch).max() < 1.2 and np.abs(roll_pitch).max() > 0.3


def test_cart_manoeuvres_come_in_bursts():
    traj = Trajectory(Cart(SQUARE, yaw_swing_deg=30.0, swing_burst_s=5.0), duration=100.0)
    t = np.linspace(0, 20, 2001)
    _, rot = traj.pose(t)
    rate = (rot[1:] * rot[:-1].inv()).magnitude() / np.diff(t)
    calm, busy = (t[1:] % 10) > 5.5, np.abs((t[1:] % 10) - 2.5) < 1.0
    assert rate[busy].max() > 1.0 and rate[calm].max() < 0.3


def test_mocap_stream_noise_and_observer_quaternions():
    traj = Trajectory(Cart(SQUARE), duration=100.0)
    stamps = np.arange(0.0, 100.0, 0.01)
    pos, quat = mocap_stream(traj, stamps, Cart(SQUARE), np.random.default_rng(1))
    true_pos, true_rot = traj.pose(stamps)
    assert np.std(pos - true_pos) == pytest.approx(0.001, rel=0.1)
    err = np.degrees((Rotation.from_quat(quat) * true_rot.inv()).magnitude())
    assert 0.03 < np.median(err) < 0.15
    assert np.all(quat[:, 3] >= 0)  # external observer: w >= 0, so the sign flips
    yaw = attitude_deg(quat)[:, 2]
    assert np.abs(np.diff(yaw)).max() > 300  # wraps through +-180 deg on the square loop


def test_trajectory_needs_two_waypoints():
    with pytest.raises(ValueError, match="at least two"):
        Trajectory(Quadrotor(((0.0, 0.0),), altitude=5.0), duration=10.0)
