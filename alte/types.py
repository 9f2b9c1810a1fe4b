"""Core data types that flow through the pipeline: bag -> frames -> cloud -> map.

Quaternion order, stated once for the whole package: **scalar-last (x, y, z, w)**,
the order of ``scipy.spatial.transform.Rotation.from_quat`` and of ROS messages.
A pose quaternion rotates body-frame vectors into the inertial frame, so
``Rotation.from_quat(q).as_matrix()`` is the thesis' ``[DCM]_B^I`` (eq. 2.2).
Stamps are integer nanoseconds, as in ROS.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.spatial.transform import Rotation

from alte.errors import PoseError

__all__ = ["Frame", "Mount", "as_points", "thesis_mount"]

_NS = 1_000_000_000


def as_points(points: object, name: str = "points", *, owner: str = "",
              error: type[Exception] = ValueError, finite: bool = False) -> np.ndarray:
    """Return ``points`` as a C-contiguous float64 (N, 3) array or raise ``error``.

    ``owner`` prefixes the message (the function or mapper at the user's end);
    ``finite`` also rejects NaN and inf values.
    """
    where = f"{owner}: " if owner else ""
    arr = np.ascontiguousarray(points, dtype=np.float64)
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise error(f"{where}{name} must have shape (N, 3), got {arr.shape}")
    if finite and not np.isfinite(arr).all():
        raise error(f"{where}{name} contain NaN or inf values")
    return arr


@dataclass(frozen=True, eq=False)
class Frame:
    """One LiDAR scan with the vehicle pose interpolated at its stamp.

    ``points`` are in the sensor frame; ``position`` and ``quaternion`` (x, y, z, w)
    give the body pose in the inertial frame. ``pose_offset_s`` is the time from the
    scan stamp to the nearest pose sample and ``angular_rate`` the body rate (rad/s)
    there; the fast-manoeuvre filter of thesis ch. 4 uses both.
    """

    stamp: int
    points: np.ndarray
    position: np.ndarray
    quaternion: np.ndarray
    pose_offset_s: float = 0.0
    angular_rate: float = 0.0
    dropped_points: int = 0

    @property
    def time(self) -> float:
        """Stamp in seconds."""
        return self.stamp / _NS

    @property
    def rotation(self) -> Rotation:
        """Body-to-inertial rotation, ``[DCM]_B^I``."""
        return Rotation.from_quat(self.quaternion)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Frame):
            return NotImplemented
        return (
            self.stamp == other.stamp
            and np.array_equal(self.points, other.points)
            and np.array_equal(self.position, other.position)
            and np.array_equal(self.quaternion, other.quaternion)
        )

    __hash__ = None  # type: ignore[assignment]


@dataclass(frozen=True)
class Mount:
    """Fixed sensor pose on the body: offset ``R_S/B^B`` and rotation ``[DCM]_S^B``."""

    translation: np.ndarray = field(default_factory=lambda: np.zeros(3))
    quaternion: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, 0.0, 1.0]))

    def __post_init__(self) -> None:
        t = np.asarray(self.translation, dtype=np.float64).reshape(-1)
        q = np.asarray(self.quaternion, dtype=np.float64).reshape(-1)
        if t.shape != (3,) or q.shape != (4,):
            raise PoseError(f"mount needs 3 offsets and 4 quaternion values, got {t}, {q}")
        norm = float(np.linalg.norm(q))
        if not np.isfinite(norm) or norm < 1e-9:
            raise PoseError(f"mount quaternion {q.tolist()} has zero norm")
        object.__setattr__(self, "translation", t)
        object.__setattr__(self, "quaternion", q / norm)

    @property
    def rotation(self) -> Rotation:
        """Sensor-to-body rotation, ``[DCM]_S^B``."""
        return Rotation.from_quat(self.quaternion)

    @classmethod
    def from_string(cls, text: str) -> Mount:
        """Parse ``x,y,z,roll,pitch,yaw`` (metres, degrees; body axes, extrinsic xyz)."""
        try:
            values = [float(v) for v in text.split(",")]
        except ValueError as err:
            raise PoseError(f"--mount {text!r}: expected 6 numbers x,y,z,roll,pitch,yaw") from err
        if len(values) != 6:
            raise PoseError(f"--mount {text!r}: expected 6 numbers x,y,z,roll,pitch,yaw")
        quat = Rotation.from_euler("xyz", values[3:], degrees=True).as_quat()
        return cls(np.array(values[:3]), quat)

    def to_string(self) -> str:
        """Inverse of :meth:`from_string`."""
        rpy = self.rotation.as_euler("xyz", degrees=True)
        return ",".join(f"{v:.9g}" for v in [*self.translation, *rpy])


def thesis_mount() -> Mount:
    """The thesis' quadrotor mount (2.1.1, fig. 2.4): offset from the centre of mass, 30 deg down.

    Body axes are FLU (x forward, y left, z up). The VLP-16 looks along its own +y
    axis (its field of view is limited to 45 deg either side of y, thesis 2.2.1),
    so the sensor is yawed -90 deg (sensor y -> body x) and pitched 30 deg nose-down.
    """
    down = Rotation.from_euler("y", 30.0, degrees=True)
    rot = down * Rotation.from_euler("z", -90.0, degrees=True)
    return Mount(np.array([0.10, 0.0, -0.08]), rot.as_quat())
