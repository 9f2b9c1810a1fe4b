"""Sensor profiles: what the simulated VLP-16 and the vehicle's IMU do besides ray casting.

The ``thesis`` profile is the thesis' Gazebo sensor: every scan an instantaneous snapshot
from one pose, no per-point time, no IMU; the chapter tables are its reproduction. The
``uav`` profile is what a VLP-16 on a quadrotor really records:

* ``sweep``: the head spins at 600 RPM, so each firing (16 lasers, 55.6 us apart at 0.2 deg
  steps) is cast from the sensor pose at its own instant; the scan is stamped at the start
  of the rotation (azimuth -180 deg, behind the sensor) and every point carries its time
  from that stamp in a ``time`` field (float32 seconds, the Velodyne ROS driver's) or a
  ``t`` field (uint32 nanoseconds, Ouster's). With the thesis' 90 deg window the points
  are taken 37.5-62.5 ms after the stamp: recorded poses at the stamp miss the motion.
* ``imu_hz``: a ``sensor_msgs/msg/Imu`` topic in the body frame with white noise and bias
  random walk. The defaults are the RotorS / PX4 SITL Gazebo IMU plugin's (an ADIS16448,
  the flight-controller grade MEMS IMU PX4's simulator models): gyroscope noise density
  3.39e-4 rad/s/sqrt(Hz), bias random walk 3.88e-5 rad/s^2/sqrt(Hz), turn-on bias sigma
  0.5 deg/s; accelerometer 4.0e-3 m/s^2/sqrt(Hz), 6.0e-3 m/s^3/sqrt(Hz), 0.196 m/s^2
  (Kalibr's continuous-time noise model; discrete sigma = density * sqrt(rate)).
* ``imu_lead``: the IMU log begins this long before the first scan with the vehicle still
  at its start pose, as a flight log does that starts before departure (a flight
  controller logs from boot; the mission here starts with the first scan). A LiDAR-inertial
  odometry initialises its IMU biases there, as every static initialisation does.
* ``dropout``: returns lost on dark or grazing surfaces. Received power goes as
  reflectivity x cos(incidence) / range^2 (per-class reflectivity, :data:`REFLECTIVITY`);
  a return is detected with probability ``1 / (1 + (P50 / P)^4)``, ``P50`` the power of a
  10 % reflective target seen head-on at ``dropout_range`` metres.
* ``mixed_pixels``: a beam of 3 mrad divergence straddling an edge returns the mean range
  of its footprint (three sub-rays) when the two surfaces are within
  ``mix_distance`` metres of each other, creating points between them (the "edge effect").
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar, Literal

from alte.errors import ParameterError
from alte.params import Record, param

__all__ = ["PROFILES", "REFLECTIVITY", "SensorProfile", "get_profile"]


def _non_negative(value: float) -> bool:
    return value >= 0


def _positive(value: float) -> bool:
    return value > 0


#: NIR reflectivity per object class (dropout model): ours, typical of the materials
#: (asphalt and soil ~0.2, concrete ~0.4-0.5, dark car paint ~0.08, foliage ~0.4).
REFLECTIVITY: dict[str, float] = {
    "ground": 0.2, "wall": 0.45, "building": 0.4, "overhang": 0.3, "beam": 0.25,
    "pillar": 0.4, "car": 0.08, "tree": 0.4, "fence": 0.3, "debris": 0.3, "buoy": 0.6,
    "room": 0.6, "vegetation": 0.4, "object": 0.3,
}


@dataclass(frozen=True)
class SensorProfile(Record):
    """What the simulated sensors do (module docstring); the default is the thesis'."""

    OWNER: ClassVar[str] = "sensor profile"
    sweep: bool = param(False, help="cast each firing from the pose at its instant and "
                                    "write per-point time")
    time_field: Literal["time", "t"] = param(
        "time", help="per-point time field: time (float32 s) or t (uint32 ns)")
    pose_hz: float = param(0.0, _non_negative, ">= 0",
                           "pose topic rate (Hz); 0: one pose per scan stamp (the thesis)")
    imu_hz: float = param(0.0, _non_negative, ">= 0", "IMU rate (Hz); 0: no IMU topic")
    gyro_noise: float = param(3.39e-4, _non_negative, ">= 0", "rad/s/sqrt(Hz)")
    gyro_walk: float = param(3.88e-5, _non_negative, ">= 0", "rad/s^2/sqrt(Hz)")
    gyro_bias: float = param(8.73e-3, _non_negative, ">= 0", "turn-on bias sigma, rad/s")
    accel_noise: float = param(4.0e-3, _non_negative, ">= 0", "m/s^2/sqrt(Hz)")
    accel_walk: float = param(6.0e-3, _non_negative, ">= 0", "m/s^3/sqrt(Hz)")
    accel_bias: float = param(0.196, _non_negative, ">= 0", "turn-on bias sigma, m/s^2")
    imu_lead: float = param(0.0, _non_negative, ">= 0",
                            "s of IMU before the first scan, the vehicle still")
    dropout: bool = param(False, help="lose returns on dark or grazing surfaces")
    dropout_range: float = param(60.0, _positive, "> 0",
                                 "m; a 10 % target head-on is detected half the time here")
    mixed_pixels: bool = param(False, help="edge returns mix the ranges in the beam footprint")
    mix_distance: float = param(1.5, _positive, "> 0",
                                "m; surfaces closer than this in one footprint mix")

    @property
    def instantaneous(self) -> bool:
        """True for the thesis' sensor (nothing beyond the ray caster and range noise)."""
        return self == SensorProfile()


#: Named profiles of ``alte simulate --profile``.
PROFILES: dict[str, SensorProfile] = {
    "thesis": SensorProfile(),
    "uav": SensorProfile(sweep=True, pose_hz=50.0, imu_hz=200.0, imu_lead=2.0,
                         dropout=True),
}


def get_profile(name: str, changes: dict[str, str] | None = None) -> SensorProfile:
    """The named profile with ``changes`` (``--sensor-set key=value``) applied."""
    try:
        base = PROFILES[name]
    except KeyError as err:
        raise ParameterError(f"sensor profile: name={name!r} unknown; valid: "
                             f"{', '.join(PROFILES)}", setting="sensor profile.name") from err
    return base.replace(**changes) if changes else base
