"""Inertial navigation for LiDAR-inertial odometry: an error-state Kalman filter on the IMU.

The nominal state is the IMU's pose in the world (rotation ``R``, position ``p``), its
velocity ``v`` (world) and the gyroscope / accelerometer biases; the world's z axis points
up and gravity is ``(0, 0, -9.81)`` m/s^2. The IMU reads body rates ``w`` and specific force
``f = R^T (a - g)`` (at rest and level: ``+9.81`` along z, the ROS convention). Between two
instants the state follows the samples (each held over the half-intervals around its stamp,
so a sample is centred on the motion it measured; ``R'`` the rotation mid-step):

    a = R' (f - ba) + g;  R <- R Exp((w - bg) dt);  v <- v + a dt;  p <- p + v dt + a dt^2 / 2

and the 15-dimensional error (rotation in the IMU frame, position, velocity, biases) carries
a covariance propagated with the continuous-time noise densities of Kalibr's model
(:class:`ImuNoise`). :meth:`InertialFilter.update` is an iterated (Gauss-Newton) update of
the pose with a batch of linearised residuals, as FAST-LIO's iterated EKF: what the LiDAR
does not constrain (flat ground says nothing of x, y and yaw) stays with the IMU.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from alte.params import Record, param

__all__ = ["GRAVITY", "STEADY_TURN", "ImuNoise", "InertialFilter", "NavState", "Residuals", "hat",
           "integrate", "still", "strong_directions"]

GRAVITY = np.array([0.0, 0.0, -9.81])
#: How many turn-on sigmas a still gyroscope's mean rate may reach: the norm of three
#: N(0, 1) biases exceeds it with probability 1e-4 (sqrt of chi2(3)'s 0.9999 quantile).
STEADY_TURN = 4.594

#: Residuals ``r`` (M,) and their Jacobian (M, 6) in (rotation, position) of the IMU.
Residuals = tuple[NDArray[np.float64], NDArray[np.float64]]


def _positive(value: float) -> bool:
    return value > 0


def hat(v: NDArray[np.float64]) -> NDArray[np.float64]:
    """Skew-symmetric matrix of a 3-vector (``hat(a) @ b == cross(a, b)``)."""
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


@dataclass(frozen=True)
class ImuNoise(Record):
    """Continuous-time noise densities: white noise and bias random walk; turn-on bias
    sigmas (the ADIS16448's figures by default)."""

    OWNER = "imu noise"

    gyro: float = param(3.39e-4, _positive, "gyro > 0",
                        "gyroscope white noise (rad/s/sqrt(Hz))")
    accel: float = param(4.0e-3, _positive, "accel > 0",
                         "accelerometer white noise (m/s^2/sqrt(Hz))")
    gyro_walk: float = param(3.88e-5, _positive, "gyro_walk > 0",
                             "gyroscope bias random walk (rad/s^2/sqrt(Hz))")
    accel_walk: float = param(6.0e-3, _positive, "accel_walk > 0",
                              "accelerometer bias random walk (m/s^3/sqrt(Hz))")
    gyro_bias: float = param(8.73e-3, _positive, "gyro_bias > 0",
                             "gyroscope turn-on bias sigma (rad/s)")
    accel_bias: float = param(0.196, _positive, "accel_bias > 0",
                              "accelerometer turn-on bias sigma (m/s^2)")


@dataclass
class NavState:
    """The nominal state at ``stamp`` (ns): IMU rotation (world from IMU), position,
    velocity, gyroscope and accelerometer biases."""

    stamp: int
    rotation: Rotation[tuple[()]]
    position: NDArray[np.float64]
    velocity: NDArray[np.float64]
    gyro_bias: NDArray[np.float64]
    accel_bias: NDArray[np.float64]

    def copy(self) -> NavState:
        """An independent copy."""
        return NavState(self.stamp, Rotation.from_quat(self.rotation.as_quat()),
                        self.position.copy(), self.velocity.copy(), self.gyro_bias.copy(),
                        self.accel_bias.copy())

    def matrix(self) -> NDArray[np.float64]:
        """The IMU pose as a 4x4 transform (world from IMU)."""
        out = np.eye(4)
        out[:3, :3] = self.rotation.as_matrix()
        out[:3, 3] = self.position
        return out


def _steps(stamps: NDArray[np.int64], start: int, end: int,
           ) -> tuple[NDArray[np.int64], NDArray[np.intp]]:
    """Sub-intervals of ``[start, end]`` (ns) split at the midpoints between samples, and the
    index of the sample that covers each (the one whose stamp is nearest its middle)."""
    mids = (stamps[:-1] + stamps[1:]) // 2
    inside = mids[(mids > start) & (mids < end)]
    bounds = np.r_[start, inside, end].astype(np.int64)
    centre = (bounds[:-1] + bounds[1:]) // 2
    index = np.clip(np.searchsorted(mids, centre, side="right"), 0, len(stamps) - 1)
    return bounds, index


def integrate(state: NavState, end: int, stamps: NDArray[np.int64], gyro: NDArray[np.float64],
              accel: NDArray[np.float64], *,
              visit: Callable[[NavState, NDArray[np.float64], NDArray[np.float64], float],
                              None] | None = None,
              ) -> NavState:
    """The nominal state carried from ``state.stamp`` to ``end`` (ns) by the samples
    (module docstring); ``visit(state, w, f, dt)`` sees each step before it is applied."""
    out = state.copy()
    if end <= out.stamp or len(stamps) == 0:
        return out
    bounds, index = _steps(stamps, out.stamp, end)
    for k, dt_ns in zip(index, np.diff(bounds), strict=True):
        dt = dt_ns * 1e-9
        w, f = gyro[k] - out.gyro_bias, accel[k] - out.accel_bias
        if visit is not None:
            visit(out, w, f, dt)
        turned = out.rotation * Rotation.from_rotvec(w * dt)
        mid = out.rotation * Rotation.from_rotvec(0.5 * w * dt)
        acc = mid.apply(f) + GRAVITY  # the force turns with the body over the step
        out.position = out.position + out.velocity * dt + 0.5 * acc * dt * dt
        out.velocity = out.velocity + acc * dt
        out.rotation = turned
    out.stamp = int(end)
    return out


def strong_directions(jac: NDArray[np.float64], weight: NDArray[np.float64], least: float,
            lever: float = 10.0) -> NDArray[np.float64]:
    """Projector (6x6) onto the pose directions that residuals of Jacobian ``jac`` and
    weights ``weight`` inform at least ``least`` (1/m^2; a rotation counts as the motion
    it gives ``lever`` metres away). Over flat ground seen through a narrow window, x, y
    and yaw get a little information from plane normals tilted by noise and by the map's
    own small tilts (10-20 /m^2 a scan on sim_lan_1, against 90-200 when a building is in
    view): false fixes, which the filter would fold into velocity and accelerometer
    bias."""
    scale = np.r_[np.full(3, lever), np.ones(3)]
    scaled = jac / scale
    values, vectors = np.linalg.eigh(scaled.T @ (scaled * weight[:, None]))
    strong = vectors[:, values >= least]
    out: NDArray[np.float64] = (strong @ strong.T) * scale[None, :] / scale[:, None]
    return out


def still(gyro: NDArray[np.float64], accel: NDArray[np.float64], noise: ImuNoise,
          rate_hz: float) -> int:
    """How many of the first IMU samples were taken at rest (0 when under 0.5 s of them):
    those before the first sample off the median by more than four white-noise sigmas
    (plus 0.005 rad/s, 0.05 m/s^2 of vibration), with a mean rate a turn-on bias
    explains (a steady turn is not a bias): its norm within the chi (3 axes) quantile
    :data:`STEADY_TURN` of the turn-on sigma, 4.6 sigmas. A bound of 3 sigmas on the norm
    refused the rest of 2.9 % of IMUs, whose biases then had to be learned in flight: a
    1.6 deg/s yaw bias, 3.2 sigmas, turned the first scans' map by a degree."""
    root = np.sqrt(rate_hz)
    if len(gyro) < 0.5 * rate_hz:
        return 0
    off = np.any(np.abs(gyro - np.median(gyro, axis=0)) > 4 * noise.gyro * root + 0.005,
                 axis=1) | np.any(np.abs(accel - np.median(accel, axis=0))
                                  > 4 * noise.accel * root + 0.05, axis=1)
    count = int(np.argmax(off)) if off.any() else len(off)
    if count < 0.5 * rate_hz or np.linalg.norm(gyro[:count].mean(axis=0)) \
            >= STEADY_TURN * noise.gyro_bias:
        return 0
    return count


class InertialFilter:
    """Error-state Kalman filter of :class:`NavState` (module docstring)."""

    def __init__(self, state: NavState, noise: ImuNoise, *, velocity_sigma: float = 1.0,
                 attitude_sigma: float = 0.02, heading_sigma: float = 1e-3) -> None:
        """``attitude_sigma`` (rad): roll and pitch against gravity; ``heading_sigma``:
        yaw, which the first pose defines (the world frame is its heading), so it is
        known (to 1 mrad: tighter, and the tilt-bias coupling of :meth:`settle` leaves the
        information matrix too ill-conditioned to invert); a yaw as uncertain as the tilt
        lets the first scans' biased plane fits turn the map by tenths of a degree."""
        self.state, self.noise = state, noise
        diag = np.r_[np.zeros(3), np.full(3, 1e-6),
                     np.full(3, velocity_sigma**2), np.full(3, noise.gyro_bias**2),
                     np.full(3, noise.accel_bias**2)]
        self.cov = np.diag(diag)
        rot = state.rotation.as_matrix()  # world from IMU: the error lives in the IMU frame
        world = np.diag([attitude_sigma**2, attitude_sigma**2, heading_sigma**2])
        self.cov[0:3, 0:3] = rot.T @ world @ rot

    def settle(self, gyro: NDArray[np.float64], accel: NDArray[np.float64]) -> None:
        """Start from rest (static initialisation): the velocity is zero, the gyroscope
        bias the mean rate and the accelerometer bias the mean force less gravity seen
        in the current attitude. That bias is only as good as the attitude: its error is
        ``-[u]x`` times the attitude error (``u`` gravity in the IMU frame), so the LiDAR's
        ground, which fixes roll and pitch, fixes the bias with them."""
        count = len(gyro)
        u = self.state.rotation.inv().apply(-GRAVITY)
        self.state.velocity = np.zeros(3)
        self.state.gyro_bias = gyro.mean(axis=0)
        self.state.accel_bias = accel.mean(axis=0) - u
        cov, coupling = self.cov, -hat(u)
        cov[6:15, :] = 0.0
        cov[:, 6:15] = 0.0
        cov[6:9, 6:9] = np.eye(3) * 0.01**2
        cov[9:12, 9:12] = np.diag(gyro.var(axis=0) / count + 1e-10)
        cov[12:15, 0:3] = coupling @ cov[0:3, 0:3]
        cov[0:3, 12:15] = cov[12:15, 0:3].T
        cov[12:15, 12:15] = coupling @ cov[0:3, 0:3] @ coupling.T \
            + np.diag(accel.var(axis=0) / count + 1e-8)

    def _covariance_step(self, state: NavState, w: NDArray[np.float64], f: NDArray[np.float64],
                         dt: float) -> None:
        """Propagate the error covariance over one step (state before the step)."""
        n = self.noise
        rot = state.rotation.as_matrix()
        jac = np.eye(15)
        jac[0:3, 0:3] = Rotation.from_rotvec(-w * dt).as_matrix()
        jac[0:3, 9:12] = -np.eye(3) * dt
        jac[3:6, 6:9] = np.eye(3) * dt
        jac[6:9, 0:3] = -rot @ hat(f) * dt
        jac[6:9, 12:15] = -rot * dt
        q = np.r_[np.full(3, n.gyro**2 * dt), np.zeros(3), np.full(3, n.accel**2 * dt),
                  np.full(3, n.gyro_walk**2 * dt), np.full(3, n.accel_walk**2 * dt)]
        self.cov = jac @ self.cov @ jac.T + np.diag(q)

    def predict(self, end: int, stamps: NDArray[np.int64], gyro: NDArray[np.float64],
                accel: NDArray[np.float64]) -> None:
        """Carry state and covariance to ``end`` (ns) with the IMU samples."""
        self.state = integrate(self.state, end, stamps, gyro, accel,
                               visit=self._covariance_step)

    def apply(self, delta: NDArray[np.float64], base: NavState) -> NavState:
        """``base`` moved by the 15-dimensional error ``delta``."""
        out = base.copy()
        out.rotation = base.rotation * Rotation.from_rotvec(delta[0:3])
        out.position = base.position + delta[3:6]
        out.velocity = base.velocity + delta[6:9]
        out.gyro_bias = base.gyro_bias + delta[9:12]
        out.accel_bias = base.accel_bias + delta[12:15]
        return out

    def update(self,
               residuals: Callable[[NavState], Residuals], sigma: float,
               iterations: int = 5, tolerance: float = 1e-4, least: float = 0.0) -> int:
        """Iterated update with ``residuals(state) -> (r, J)`` (:data:`Residuals`) of noise
        ``sigma``, down-weighted beyond ``sigma`` by a Cauchy kernel (outliers: planes
        fitted across two objects). Directions of the pose the batch informs less than
        ``least`` keep the prediction (:func:`strong_directions`; 0: every direction).
        Returns the count of residuals of the last iteration (0: no update)."""
        prior = self.state
        info_prior = np.linalg.inv(self.cov)
        delta: NDArray[np.float64] = np.zeros(15)
        count = 0
        for _ in range(iterations):
            r, jac = residuals(self.apply(delta, prior))
            count = len(r)
            if count < 6:
                return 0
            weight = 1.0 / (1.0 + (r / sigma) ** 2) / sigma**2
            h = np.zeros((count, 15))
            h[:, :6] = jac if least <= 0 else jac @ strong_directions(jac, weight, least)
            info = info_prior + h.T @ (h * weight[:, None])
            rhs = h.T @ (weight * (h @ delta - r))
            new = np.asarray(np.linalg.solve(info, rhs), dtype=np.float64)
            step, delta = new - delta, new
            if np.linalg.norm(step[:6]) < tolerance:
                break
        self.state = self.apply(delta, prior)
        self.cov = np.linalg.inv(info)
        self.cov = 0.5 * (self.cov + self.cov.T)
        return count
