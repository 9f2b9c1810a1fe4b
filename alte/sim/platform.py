"""Platforms and pose streams: the quadrotor (simulated cases) and the tripod cart
(experimental cases), thesis 2.1.1 and 2.2.3-2.2.4.

A trajectory is a smooth function of time: a cubic spline through the waypoints,
travelled at constant speed with smooth start/stop ramps. The quadrotor flies at a
constant altitude with its yaw along the path and tilts to accelerate; the cart
carries the sensor on a tripod with small roll/pitch wobble and, when the operator
manoeuvres, fast yaw swings that rock the tripod (in bursts when ``swing_burst_s``
is set). Pose streams are Gazebo's true state at scan rate or
a motion-capture stream (100 Hz, millimetre noise, attitude reported by an external
observer as a quaternion with ``w >= 0``, so its sign and Euler angles wrap).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.interpolate import CubicSpline
from scipy.spatial.transform import Rotation

from alte.types import Mount

__all__ = ["Cart", "Quadrotor", "Trajectory", "mocap_stream",
           "tripod_mount"]

_G = 9.81


@dataclass(frozen=True)
class Quadrotor:
    """Waypoint flight at constant altitude (thesis 2.1.1); mount: ``thesis_mount()``.

    ``heights`` (over real terrain) replaces the constant altitude by a height profile:
    heights at evenly spaced points of the path's spline parameter, from its first
    waypoint to its last, linearly interpolated between them.
    """

    waypoints: tuple[tuple[float, float], ...]
    altitude: float
    ramp_s: float = 3.0
    heights: tuple[float, ...] | None = None


@dataclass(frozen=True)
class Cart:
    """Tripod cart pushed by hand; the pose stream is the sensor marker's (VICON)."""

    waypoints: tuple[tuple[float, float], ...]
    height: float = 1.8
    ramp_s: float = 2.0
    wobble_deg: float = 1.0
    yaw_swing_deg: float = 0.0
    yaw_swing_hz: float = 0.5
    swing_burst_s: float = 0.0
    sway_deg: float = 0.0
    time_offset_s: float = 0.01
    jitter_s: float = 0.005
    mocap_hz: float = 100.0
    position_sigma: float = 0.001
    attitude_sigma_deg: float = 0.05
    phases: tuple[float, ...] = field(default=(0.3, 1.7, 2.9, 4.1))


def tripod_mount() -> Mount:
    """Sensor on the tripod relative to its VICON object frame.

    The VICON object (thesis 2.2.3, fig. 2.18) is defined level with x along the
    cart's heading and its origin 5 cm above the sensor's optical centre; the sensor
    looks along that heading (its +y) tilted 30 deg down so the floor and obstacles
    from 1.8 m to 6.7 m ahead are in its +-15 deg beams.
    """
    down = Rotation.from_euler("y", 30.0, degrees=True)
    return Mount(np.array([0.0, 0.0, -0.05]), (down * Rotation.from_euler("z", -90.0,
                                                                          degrees=True)).as_quat())


class Trajectory:
    """Body pose along a waypoint path as a function of time (seconds from start)."""

    def __init__(self, platform: Quadrotor | Cart, duration: float) -> None:
        pts = np.asarray(platform.waypoints, dtype=np.float64)
        if pts.ndim != 2 or pts.shape[1] != 2 or len(pts) < 2:
            raise ValueError("a trajectory needs at least two (x, y) waypoints")
        chord = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(pts, axis=0), axis=1))]
        self._spline = CubicSpline(chord, pts, bc_type="natural")
        u = np.linspace(0.0, chord[-1], 20_000)
        step = np.linalg.norm(np.diff(self._spline(u), axis=0), axis=1)
        self._u, self._s = u, np.r_[0.0, np.cumsum(step)]
        self.platform, self.duration, self.length = platform, float(duration), float(self._s[-1])
        ramp = min(platform.ramp_s, 0.25 * duration)
        self._speed = self.length / (duration - ramp)
        self._ramp = ramp

    @property
    def parameter_range(self) -> tuple[float, float]:
        """The spline parameter at the first and the last waypoint."""
        return float(self._u[0]), float(self._u[-1])

    def path_xy(self, u: NDArray[np.float64]) -> NDArray[np.float64]:
        """Horizontal positions (K, 2) at spline parameters ``u``."""
        xy: NDArray[np.float64] = self._spline(np.asarray(u, dtype=np.float64))
        return xy

    @property
    def speed(self) -> float:
        """Cruise speed (m/s)."""
        return self._speed

    def _distance(self, t: NDArray[np.float64]) -> NDArray[np.float64]:
        """Travelled distance: constant speed with smooth (cosine) ramps at both ends."""
        r, v, d = self._ramp, self._speed, self.duration
        tc = np.clip(t, 0.0, d)

        def ramp_dist(x: ArrayLike) -> NDArray[np.float64]:  # integral of v (1 - cos(pi x / r)) / 2
            xc = np.clip(x, 0.0, r)
            dist: NDArray[np.float64] = 0.5 * v * (xc - r / np.pi * np.sin(np.pi * xc / r))
            return dist

        travelled: NDArray[np.float64] = ramp_dist(tc) + v * np.clip(tc - r, 0.0, d - 2 * r) + (
            ramp_dist(r) - ramp_dist(d - tc)) * (tc > d - r)
        return travelled

    def xy(self, t: NDArray[np.float64]) -> NDArray[np.float64]:
        """Horizontal position (K, 2) at times ``t``."""
        return self._spline(np.interp(self._distance(np.asarray(t, float)), self._s, self._u))

    def heading(self, t: NDArray[np.float64]) -> NDArray[np.float64]:
        """Path tangent direction (rad), defined even when stopped."""
        u = np.interp(self._distance(np.asarray(t, float)), self._s, self._u)
        du = self._spline(u, 1)
        return np.unwrap(np.arctan2(du[:, 1], du[:, 0]))

    def _height(self, t: NDArray[np.float64], quad: Quadrotor) -> NDArray[np.float64]:
        """The flight height at ``t``: constant, or the quadrotor's height profile."""
        if quad.heights is None:
            return np.full(len(t), quad.altitude)
        u = np.interp(self._distance(t), self._s, self._u)
        knots = np.linspace(self._u[0], self._u[-1], len(quad.heights))
        return np.interp(u, knots, np.asarray(quad.heights, dtype=np.float64))

    def pose(self, t: NDArray[np.float64]) -> tuple[NDArray[np.float64], Rotation[tuple[int, ...]]]:
        """Body position (K, 3) and body-to-inertial rotation at times ``t``."""
        t = np.atleast_1d(np.asarray(t, dtype=np.float64))
        if isinstance(self.platform, Quadrotor):
            return self._quadrotor_pose(t, self.platform)
        return self._cart_pose(t, self.platform)

    def _quadrotor_pose(self, t: NDArray[np.float64], quad: Quadrotor
                        ) -> tuple[NDArray[np.float64], Rotation[tuple[int, ...]]]:
        h = 0.02
        acc = (self.xy(t + h) - 2 * self.xy(t) + self.xy(t - h)) / h**2
        yaw = self.heading(t)
        fwd = acc[:, 0] * np.cos(yaw) + acc[:, 1] * np.sin(yaw)
        lat = -acc[:, 0] * np.sin(yaw) + acc[:, 1] * np.cos(yaw)
        pitch, roll = np.arctan(fwd / _G), -np.arctan(lat / _G)
        pos = np.column_stack([self.xy(t), self._height(t, quad)])
        return pos, Rotation.from_euler("ZYX", np.column_stack([yaw, pitch, roll]))

    def _cart_pose(self, t: NDArray[np.float64], cart: Cart
                   ) -> tuple[NDArray[np.float64], Rotation[tuple[int, ...]]]:
        ph = cart.phases
        w = np.radians(cart.wobble_deg)
        roll = w * (0.6 * np.sin(2.1 * t + ph[0]) + 0.4 * np.sin(5.3 * t + ph[1]))
        pitch = w * (0.6 * np.sin(1.7 * t + ph[2]) + 0.4 * np.sin(4.4 * t + ph[3]))
        burst = np.ones_like(t)
        if cart.swing_burst_s > 0:  # manoeuvres come in bursts, half of every 2 x burst period
            phase = np.sin(np.pi * t / cart.swing_burst_s)
            burst = phase**2 * (phase > 0)
        omega = 2 * np.pi * cart.yaw_swing_hz
        swing = burst * np.radians(cart.yaw_swing_deg) * np.sin(omega * t)
        sway = burst * np.radians(cart.sway_deg)  # the tripod rocks when jerked around
        roll = roll + sway * np.sin(1.9 * omega * t + ph[1])
        pitch = pitch + sway * np.sin(1.3 * omega * t + ph[3])
        yaw = self.heading(t) + swing
        bounce = 0.004 * np.sin(9.0 * t + ph[0])
        pos = np.column_stack([self.xy(t), cart.height + bounce])
        return pos, Rotation.from_euler("ZYX", np.column_stack([yaw, pitch, roll]))


def mocap_stream(trajectory: Trajectory, stamps_s: NDArray[np.float64], cart: Cart,
                 rng: np.random.Generator) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Motion-capture samples at ``stamps_s``: noisy positions and quaternions (w >= 0)."""
    pos, rot = trajectory.pose(stamps_s)
    pos = pos + rng.normal(0.0, cart.position_sigma, pos.shape)
    tilt = Rotation.from_rotvec(rng.normal(0.0, np.radians(cart.attitude_sigma_deg), pos.shape))
    quat = (tilt * rot).as_quat(canonical=True)
    return pos, quat
