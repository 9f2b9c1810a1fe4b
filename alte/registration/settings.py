"""What odometry and refinement are asked to do (:class:`OdometrySettings`, checked as
``--odometry`` / ``--odometry-set``) and what they report (:class:`PoseCounts`).

Apart from :mod:`~alte.registration.odometry` so that its backends and refinement read
them without importing the module that drives them.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from typing import ClassVar, Literal, get_args

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from alte.errors import ParameterError
from alte.params import Record, param
from alte.registration.inertial import ImuNoise
from alte.types import Counts

__all__ = ["KEYS", "METHODS", "OdometrySettings", "PoseCounts", "odometry_label",
           "odometry_params", "pose_matrix", "resolve_method"]

#: Odometry backends (module docstring).
OdometryMethod = Literal["auto", "kiss", "plane", "lio"]
METHODS: tuple[str, ...] = get_args(OdometryMethod)
#: The LIO's IMU figures unless set (the ADIS16448's, as the simulator's ``uav`` profile).
_IMU = ImuNoise()


def _positive(value: float) -> bool:
    return value > 0


def _fraction(value: float) -> bool:
    return 0 <= value <= 1


def _imu(default: float, unit: str, what: str) -> float:
    """One of the LIO's IMU figures (:class:`~alte.registration.inertial.ImuNoise`)."""
    return param(default, _positive, "> 0", f"{unit}; lio: the IMU's {what}")


@dataclass(frozen=True)
class OdometrySettings(Record):
    """How scans are aligned by odometry (``method``) and refinement; unset values come
    from KISS-ICP's defaults or the first scan's ranges (:mod:`~alte.registration.backends`)."""

    OWNER: ClassVar[str] = "odometry"
    method: OdometryMethod = param("auto",
                                   help="odometry backend (auto: lio with an IMU topic, else kiss)")
    max_range: float | None = param(None, _positive, "> 0",
                                    "m; points beyond are not used (kiss: 100, plane: 1.2 x "
                                    "the 99th percentile range of the first scan)")
    min_range: float = param(0.0, lambda v: v >= 0, ">= 0", "m; nearer points are not used "
                                                            "(kiss)")
    voxel: float | None = param(None, _positive, "> 0",
                                "m; map voxel (kiss: 1.5 x max_range / 100 with the window, "
                                "KISS-ICP's max_range / 100 without; plane and refine: the "
                                "median range of the first scan / 70; lio: 0.5)")
    single_downsample: bool = param(False, help="kiss: register the 0.5-voxel cloud (sparse "
                                                "sensors' advice)")
    fixed_threshold: float | None = param(None, _positive, "> 0",
                                          "m; kiss: fixed correspondence threshold instead "
                                          "of the adaptive one")
    initial_threshold: float = param(2.0, _positive, "> 0",
                                     "m; kiss: adaptive threshold before any motion")
    min_motion_th: float = param(0.1, _positive, "> 0",
                                 "m; kiss: least motion that updates the adaptive threshold")
    max_points_per_voxel: int | None = param(None, lambda v: v >= 1, ">= 1",
                                             "kiss: map points per voxel (10 with the "
                                             "window, KISS-ICP's 20 without)")
    deskew: bool = param(True, help="kiss: deskew scans that carry per-point time")
    window: int = param(20, lambda v: v >= 0, ">= 0",
                        "kiss: each pose re-aligned to this many scans before and after it "
                        "once they have arrived (0: off; poses lag by as many scans)")
    window_voxel: float | None = param(None, _positive, "> 0",
                                       "m; kiss: the window's Gaussian voxel map (max_range / "
                                       "100), scans down-sampled at a quarter of it")
    threads: int = param(1, lambda v: v >= 0, ">= 0", "threads per scan (0: every core)")
    rebuild: int = param(5, lambda v: v >= 1, ">= 1",
                         "plane, refine: scans between local-map rebuilds")
    min_fitness: float = param(0.3, _fraction, "0..1",
                               "plane, refine: fewest inliers (fraction of the scan) for an "
                               "alignment to count")
    min_constraint: float = param(0.002, _fraction, "0..1",
                                  "refine: smallest / largest Hessian eigenvalue to accept")
    min_gain: float = param(0.3, _fraction, "0..1",
                            "refine: least share of the scan's cost (truncated at 3 noise "
                            "sigmas) a correction must remove to be applied")
    min_information: float = param(0.0, _fraction, "0..1",
                                   "refine: least information (Hessian per point) along "
                                   "the corrected direction for a correction to be applied "
                                   "(0: any)")
    max_correction: float = param(0.5, _positive, "> 0",
                                  "m; refine: a larger correction is not applied")
    max_correction_deg: float = param(20.0, _positive, "> 0",
                                      "deg; refine: a larger correction is not applied")
    plane_sigma: float = param(0.15, _positive, "> 0",
                               "m; lio: point-to-plane noise (Cauchy kernel width)")
    plane_reach: float = param(2.0, _positive, "> 0",
                               "m; lio: farthest map neighbour of a small plane fit")
    plane_points: int = param(5, lambda v: v >= 3, ">= 3",
                              "lio: map points of a small plane fit (used where the 20 "
                              "within 3 m are not flat)")
    wide_points: int = param(20, lambda v: v == 0 or v >= 3, "0 or >= 3",
                             "lio: map points of the plane fit across scan rings (0: small "
                             "fits only)")
    wide_reach: float = param(3.0, _positive, "> 0",
                              "m; lio: farthest map neighbour of the plane fit across rings")
    least: float = param(30.0, lambda v: v >= 0, ">= 0",
                         "1/m^2; lio: least information a scan gives a pose direction for "
                         "the update to move it (0: every direction)")
    gyro_noise: float = _imu(_IMU.gyro, "rad/s/sqrt(Hz)", "gyroscope white noise "
                             "(Kalibr's gyroscope_noise_density; unset: the ADIS16448's)")
    accel_noise: float = _imu(_IMU.accel, "m/s^2/sqrt(Hz)", "accelerometer white noise")
    gyro_walk: float = _imu(_IMU.gyro_walk, "rad/s^2/sqrt(Hz)", "gyroscope bias random walk")
    accel_walk: float = _imu(_IMU.accel_walk, "m/s^3/sqrt(Hz)", "accelerometer bias random walk")
    gyro_bias: float = _imu(_IMU.gyro_bias, "rad/s", "gyroscope turn-on bias sigma (what a "
                                                      "still start may read as bias)")
    accel_bias: float = _imu(_IMU.accel_bias, "m/s^2", "accelerometer turn-on bias sigma")
    imu_topic: str | None = param(None, bool, "a topic name",
                                  "lio: the IMU topic (default: the bag's only "
                                  "sensor_msgs/msg/Imu)")


#: The settings each backend reads (``refine`` is ``--poses refine``); ``threads`` and the
#: ranges are shared.
KEYS: dict[str, tuple[str, ...]] = {
    "kiss": ("max_range", "min_range", "voxel", "single_downsample", "fixed_threshold",
             "initial_threshold", "min_motion_th", "max_points_per_voxel", "deskew", "window",
             "window_voxel", "threads"),
    "plane": ("max_range", "voxel", "rebuild", "min_fitness"),
    "lio": ("max_range", "min_range", "voxel", "plane_sigma", "plane_reach", "plane_points",
            "wide_points", "wide_reach", "least", "gyro_noise", "accel_noise", "gyro_walk",
            "accel_walk", "gyro_bias", "accel_bias", "imu_topic"),
    "refine": ("max_range", "voxel", "rebuild", "min_fitness", "min_constraint", "min_gain",
               "min_information", "max_correction", "max_correction_deg", "threads"),
}
KEYS["auto"] = tuple(dict.fromkeys(KEYS["kiss"] + KEYS["lio"]))


def odometry_params(method: str | None = None, settings: Mapping[str, object] | None = None
                    ) -> OdometrySettings:
    """The backend ``method`` with its ``settings`` (text or typed) checked; an error names
    the setting (``odometry.method``, else ``odometry.settings``: the command line's
    ``--odometry`` / ``--odometry-set``)."""
    settings = dict(settings or {})
    if method is not None and method not in METHODS:
        raise ParameterError(f"odometry: method={method!r} unknown; valid: "
                             f"{', '.join(METHODS)}", setting="odometry.method")
    chosen = method or OdometrySettings().method
    valid = set(KEYS[chosen]) | set(KEYS["refine"])
    unknown = sorted(set(settings) - valid)
    if unknown:
        raise ParameterError(f"odometry: {', '.join(unknown)}: not a setting of method={chosen} "
                             f"or refinement; valid: {', '.join(sorted(valid))}",
                             setting="odometry.settings")
    try:
        return OdometrySettings.parse({"method": chosen, **settings})
    except ParameterError as err:
        err.settings = ("odometry.settings",)
        raise


def odometry_label(params: OdometrySettings) -> str:
    """``kiss-icp`` or ``point-to-plane``, with the settings that differ from the defaults."""
    name = {"auto": "auto", "kiss": "kiss-icp", "plane": "point-to-plane",
            "lio": "lidar-inertial"}[params.method]
    default = OdometrySettings(method=params.method).as_dict()
    changed = [f"{k}={v}" for k, v in params.as_dict().items()
               if v != default[k] and k in KEYS[params.method]]
    return f"{name} {' '.join(changed)}" if changed else name


@dataclass
class PoseCounts(Counts):
    """Where the poses came from, what odometry / refinement did and how long it took
    (``seconds``: the pose step alone, wall; ``cpu_seconds``: its thread's CPU time);
    ``scans``: refinement's decision per scan; ``rest_s``: the still IMU the LiDAR-inertial
    odometry started from, s (0: none, it started in motion)."""

    source: str = "recorded"
    method: str = ""
    settings: dict[str, object] = field(default_factory=dict)
    frames: int = 0
    deskewed: int = 0
    rest_s: float = 0.0
    corrected: int = 0
    realigned: int = 0
    kept: dict[str, int] = field(default_factory=dict)
    weak_alignments: int = 0
    max_correction_m: float = 0.0
    max_correction_deg: float = 0.0
    seconds: float = 0.0
    cpu_seconds: float = 0.0
    scans: list[dict[str, object]] = field(default_factory=list)


def pose_matrix(position: NDArray[np.float64], quaternion: NDArray[np.float64],
                ) -> NDArray[np.float64]:
    """4x4 homogeneous transform of a position and an (x, y, z, w) quaternion."""
    out = np.eye(4)
    out[:3, :3] = Rotation.from_quat(quaternion).as_matrix()
    out[:3, 3] = position
    return out


def resolve_method(params: OdometrySettings, has_imu: bool) -> OdometrySettings:
    """``auto`` made concrete: ``lio`` when the bag has an IMU topic, else ``kiss``."""
    if params.method != "auto":
        return params
    return replace(params, method="lio" if has_imu else "kiss")
