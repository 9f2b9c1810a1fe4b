"""The vehicle's IMU: body rates and specific force along the trajectory, with MEMS noise.

The IMU sits on the body at :data:`IMU_MOUNT` (a flight controller 3 cm above the centre
of mass, its axes the body's FLU axes). At each sample the true angular rate is the mean
rate over the sample interval (the rotation between the half-interval neighbours) and
the true specific force ``R^T (a + g e_z)`` with ``a`` the second difference of the
IMU's own position over one interval, so integrating the noise-free samples retraces
the trajectory. Noise follows Kalibr's model: white noise of density ``sigma`` gives
``sigma * sqrt(rate)`` per sample; the bias starts at N(0, turn-on sigma) and walks by
``sigma_walk * sqrt(dt)`` per sample (figures: :mod:`alte.sim.profile`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from alte.sim.platform import Trajectory
from alte.sim.profile import SensorProfile
from alte.types import Mount

__all__ = ["GRAVITY", "IMU_MOUNT", "ImuStream", "imu_stream", "true_imu"]

GRAVITY = 9.81
#: Where the IMU sits on the body (axes aligned with the body's).
IMU_MOUNT = Mount(np.array([0.0, 0.0, 0.03]))


@dataclass(frozen=True, eq=False)
class ImuStream:
    """IMU samples: stamps (N,) int64 ns, gyro (N, 3) rad/s, accel (N, 3) m/s^2 in the
    IMU frame; the biases (N, 3) each sample carries (the truth, for tests)."""

    stamps: NDArray[np.int64]
    angular_velocity: NDArray[np.float64]
    linear_acceleration: NDArray[np.float64]
    gyro_bias: NDArray[np.float64]
    accel_bias: NDArray[np.float64]
    mount: Mount
    gyro_sigma: float
    accel_sigma: float

    def __len__(self) -> int:
        return int(self.stamps.shape[0])


def true_imu(trajectory: Trajectory, times: NDArray[np.float64], rate_hz: float,
             mount: Mount = IMU_MOUNT) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Noise-free gyro (N, 3) and accelerometer (N, 3) readings at ``times`` (s)."""
    t = np.asarray(times, dtype=np.float64)
    dt = 1.0 / rate_hz
    _, before = trajectory.pose(t - dt / 2)
    _, after = trajectory.pose(t + dt / 2)
    gyro_body = (before.inv() * after).as_rotvec() / dt
    positions = []
    rotation = None
    for shift in (-dt, 0.0, dt):
        pos, rot = trajectory.pose(t + shift)
        positions.append(pos + rot.apply(mount.translation))
        if shift == 0.0:
            rotation = pos, rot
    assert rotation is not None
    accel = (positions[0] - 2 * positions[1] + positions[2]) / dt**2
    accel[:, 2] += GRAVITY
    to_imu = mount.rotation.inv()
    specific = to_imu.apply(rotation[1].inv().apply(accel))
    return to_imu.apply(gyro_body), specific


def _noise(n: int, rate: float, figures: tuple[float, float, float],
           rng: np.random.Generator) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """White noise (N, 3) and bias (N, 3) of one sensor triad: ``figures`` are the white
    noise density, the bias random walk and the turn-on bias sigma."""
    white, walk, turn_on = figures
    bias0 = rng.normal(0.0, turn_on, 3)
    steps = rng.normal(0.0, walk / np.sqrt(rate), (n, 3))
    steps[0] = 0.0
    bias = bias0 + np.cumsum(steps, axis=0)
    return rng.normal(0.0, white * np.sqrt(rate), (n, 3)), bias


def imu_stream(trajectory: Trajectory, start_ns: int, profile: SensorProfile,
               rng: np.random.Generator, mount: Mount = IMU_MOUNT) -> ImuStream:
    """Samples at ``profile.imu_hz`` over the whole trajectory (stamps from ``start_ns``),
    and ``profile.imu_lead`` seconds before it with the vehicle still at its start."""
    rate = profile.imu_hz
    step_ns = round(1e9 / rate)
    lead = round(profile.imu_lead * 1e9) // step_ns
    count = int(trajectory.duration * 1e9) // step_ns + 1 + lead
    stamps = start_ns + step_ns * (np.arange(count, dtype=np.int64) - lead)
    gyro, accel = true_imu(trajectory, (stamps - start_ns) / 1e9, rate, mount)
    g_white, g_bias = _noise(count, rate, (profile.gyro_noise, profile.gyro_walk,
                                           profile.gyro_bias), rng)
    a_white, a_bias = _noise(count, rate, (profile.accel_noise, profile.accel_walk,
                                           profile.accel_bias), rng)
    return ImuStream(stamps, gyro + g_bias + g_white, accel + a_bias + a_white, g_bias, a_bias,
                     mount, profile.gyro_noise * np.sqrt(rate),
                     profile.accel_noise * np.sqrt(rate))
