"""Core data types that flow through the pipeline: bag -> frames -> cloud -> map.

Quaternion order, stated once for the whole package: **scalar-last (x, y, z, w)**,
the order of ``scipy.spatial.transform.Rotation.from_quat`` and of ROS messages.
A pose quaternion rotates body-frame vectors into the inertial frame, so
``Rotation.from_quat(q).as_matrix()`` is the thesis' ``[DCM]_B^I`` (eq. 2.2).
Stamps are integer nanoseconds, as in ROS.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import TypeAlias

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from alte.errors import ParameterError, PoseError

__all__ = ["JSON", "Box", "Counts", "Frame", "JSONDict", "JSONMap", "Mount", "RegisteredFrame",
           "Trajectory", "as_points", "finite_rows", "rows_all", "thesis_mount"]

_NS = 1_000_000_000

#: A value that JSON can hold (what results.json, run records and summaries carry).
JSON: TypeAlias = str | int | float | bool | Sequence["JSON"] | Mapping[str, "JSON"] | None
#: A JSON object alte builds (mutable).
JSONDict: TypeAlias = dict[str, JSON]
#: A JSON object alte reads (read-only, so a ``dict[str, float]`` fits).
JSONMap: TypeAlias = Mapping[str, JSON]


class Counts:
    """Base of the pipeline's counters (dataclasses of what a stage kept and dropped)."""

    def as_dict(self) -> dict[str, object]:
        """Counts by name (JSON-ready: lists and dicts copied)."""
        return {k: (dict(v) if isinstance(v, dict) else list(v) if isinstance(v, list) else v)
                for k, v in vars(self).items()}


def as_points(points: object, name: str = "points", *, owner: str = "",
              error: type[Exception] = ValueError, finite: bool = False,
              ) -> NDArray[np.float64]:
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


def rows_all(mask: NDArray[np.bool_]) -> NDArray[np.bool_]:
    """Row-wise ``all`` of an (N, K) boolean mask, column by column: for a few columns
    numpy's ``mask.all(axis=1)`` is several times slower (it reduces K values at a time)."""
    out = mask[:, 0].copy()
    for k in range(1, mask.shape[1]):
        out &= mask[:, k]
    return out


def finite_rows(points: NDArray[np.float64]) -> NDArray[np.bool_] | None:
    """Mask of the rows of (N, K) ``points`` with every value finite; None when all are
    (the common case, found with one fast reduction)."""
    finite = np.isfinite(points)
    return None if finite.all() else rows_all(finite)


@dataclass(frozen=True, eq=False)
class Box:
    """An axis-aligned box ``lo <= p <= hi`` (metres), e.g. a control volume (thesis 2.2.4)."""

    lo: NDArray[np.float64]
    hi: NDArray[np.float64]

    def __post_init__(self) -> None:
        lo = np.asarray(self.lo, dtype=np.float64).reshape(-1)
        hi = np.asarray(self.hi, dtype=np.float64).reshape(-1)
        if lo.shape != (3,) or hi.shape != (3,) or not (np.isfinite(lo).all()
                                                        and np.isfinite(hi).all()):
            raise ParameterError(f"box {lo.tolist()}..{hi.tolist()}: expected 3 finite "
                                 "lower and 3 finite upper bounds")
        if np.any(lo > hi):
            raise ParameterError(f"box {lo.tolist()}..{hi.tolist()}: min must be <= max")
        object.__setattr__(self, "lo", lo)
        object.__setattr__(self, "hi", hi)

    @classmethod
    def of(cls, values: object) -> Box:
        """From 6 numbers ``xmin,ymin,zmin,xmax,ymax,zmax`` (a sequence or (2, 3) array)."""
        arr = np.asarray(values, dtype=np.float64).reshape(-1)
        if arr.shape != (6,):
            raise ParameterError(f"box {np.asarray(values).tolist()}: expected 6 numbers "
                                 "xmin,ymin,zmin,xmax,ymax,zmax")
        return cls(arr[:3], arr[3:])

    @classmethod
    def around(cls, points: ArrayLike) -> Box:
        """The bounding box of (N, 3) points (N >= 1)."""
        pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        return cls(pts.min(axis=0), pts.max(axis=0))

    def values(self) -> tuple[float, ...]:
        """``(xmin, ymin, zmin, xmax, ymax, zmax)``."""
        return tuple(float(v) for v in (*self.lo, *self.hi))

    def array(self) -> NDArray[np.float64]:
        """The (2, 3) array ``[lo, hi]``."""
        return np.array([self.lo, self.hi])

    def union(self, other: Box) -> Box:
        """The smallest box holding both."""
        return Box(np.minimum(self.lo, other.lo), np.maximum(self.hi, other.hi))

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Box):
            return NotImplemented
        return bool(np.array_equal(self.lo, other.lo) and np.array_equal(self.hi, other.hi))

    # Unhashable (array fields, value equality); typeshed types __hash__ as a method.
    __hash__ = None  # type: ignore[assignment]


@dataclass(frozen=True, eq=False)
class Frame:
    """One LiDAR scan with the vehicle pose interpolated at its stamp.

    ``points`` are in the sensor frame; ``position`` and ``quaternion`` (x, y, z, w)
    give the body pose in the inertial frame. ``pose_offset_s`` is the time from the
    scan stamp to the nearest pose sample and ``angular_rate`` the body rate (rad/s)
    there; the fast-manoeuvre filter of thesis ch. 4 uses both. ``times`` (N,) holds
    each point's time in seconds from the stamp when the cloud carries one (a sweeping
    sensor: :mod:`alte.registration.deskew` uses it), else None.
    """

    stamp: int
    points: NDArray[np.float64]
    position: NDArray[np.float64]
    quaternion: NDArray[np.float64]
    pose_offset_s: float = 0.0
    angular_rate: float = 0.0
    dropped_points: int = 0
    times: NDArray[np.float64] | None = None

    @property
    def time(self) -> float:
        """Stamp in seconds."""
        return self.stamp / _NS

    @property
    def rotation(self) -> Rotation[tuple[()]]:
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

    # Unhashable (array fields, value equality); typeshed types __hash__ as a method.
    __hash__ = None  # type: ignore[assignment]


@dataclass(frozen=True, eq=False)
class RegisteredFrame:
    """One scan after registration: inertial ``points`` (N, 3) and the sensor ``origin`` (3,),
    with the scan's stamp (ns) and the body pose it was registered with; ``fields``: the
    points' other values by name (a point file's intensity, colours, ...), when kept."""

    stamp: int
    points: NDArray[np.float64]
    origin: NDArray[np.float64]
    position: NDArray[np.float64]
    quaternion: NDArray[np.float64]
    fields: dict[str, NDArray[np.generic[object]]] | None = None


@dataclass(frozen=True, eq=False)
class Trajectory:
    """The poses scans were registered with: ``stamps`` (F,) int64 ns, body ``positions``
    (F, 3) and ``quaternions`` (F, 4, x y z w), sensor ``origins`` (F, 3)."""

    stamps: NDArray[np.int64]
    positions: NDArray[np.float64]
    quaternions: NDArray[np.float64]
    origins: NDArray[np.float64]

    def __len__(self) -> int:
        return int(self.stamps.shape[0])

    @property
    def times(self) -> NDArray[np.float64]:
        """Seconds since the first stamp (F,)."""
        return (self.stamps - self.stamps[0]) / _NS if len(self) else np.empty(0)

    @classmethod
    def empty(cls) -> Trajectory:
        """No poses."""
        return cls(np.empty(0, np.int64), np.empty((0, 3)), np.empty((0, 4)), np.empty((0, 3)))

    @classmethod
    def of(cls, frames: list[RegisteredFrame]) -> Trajectory:
        """The poses of ``frames`` in order."""
        if not frames:
            return cls.empty()
        return cls(np.array([f.stamp for f in frames], np.int64),
                   np.array([f.position for f in frames], np.float64),
                   np.array([f.quaternion for f in frames], np.float64),
                   np.array([f.origin for f in frames], np.float64))


@dataclass(frozen=True)
class Mount:
    """Fixed sensor pose on the body: offset ``R_S/B^B`` and rotation ``[DCM]_S^B``."""

    translation: NDArray[np.float64] = field(default_factory=lambda: np.zeros(3))
    quaternion: NDArray[np.float64] = field(default_factory=lambda: np.array([0.0, 0.0, 0.0, 1.0]))

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
    def rotation(self) -> Rotation[tuple[()]]:
        """Sensor-to-body rotation, ``[DCM]_S^B``."""
        return Rotation.from_quat(self.quaternion)

    @classmethod
    def from_string(cls, text: str) -> Mount:
        """Parse ``x,y,z,roll,pitch,yaw`` (metres, degrees; the angle convention of
        :mod:`alte.lab.plot.scene`: intrinsic z-y-x, equal to extrinsic x-y-z)."""
        try:
            values = [float(v) for v in text.split(",")]
        except ValueError as err:
            raise PoseError(f"mount {text!r}: expected 6 numbers x,y,z,roll,pitch,yaw",
                            setting="mount") from err
        if len(values) != 6:
            raise PoseError(f"mount {text!r}: expected 6 numbers x,y,z,roll,pitch,yaw",
                            setting="mount")
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
