"""Vehicle pose tracks: clean the samples, then interpolate them at scan stamps.

Motion capture (thesis 2.2.3) and simulators report poses at their own rate, so
each scan needs the pose at its own stamp: position is interpolated linearly and
attitude by slerp between the two bracketing samples. Scans before the first or
after the last sample, or inside a gap in the track, get no pose: nothing is
extrapolated.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from functools import cached_property
from typing import NamedTuple, cast

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation, Slerp

from alte.errors import PoseError
from alte.io.bags.messages import (
    HeaderMsg,
    OdometryMsg,
    PoseMsg,
    PoseStampedMsg,
    TFMessageMsg,
    TransformStampedMsg,
)

__all__ = [
    "POSE_TYPES",
    "PoseRecord",
    "PoseSamples",
    "PoseTrack",
    "header_stamp",
    "pose_records",
    "select_tf_child",
]

_NS = 1_000_000_000
#: Message types that carry a vehicle pose.
POSE_TYPES = (
    "geometry_msgs/msg/PoseStamped",
    "nav_msgs/msg/Odometry",
    "tf2_msgs/msg/TFMessage",
)


class PoseRecord(NamedTuple):
    """One pose of a message: frames, stamp and ``(x, y, z, qx, qy, qz, qw)``."""

    parent: str
    child: str
    stamp_ns: int
    values: tuple[float, ...]


#: Factors (within 3x) that betray stamps in the wrong unit (ms or s read as ns).
_UNIT_FACTORS = {1e6: "milliseconds vs nanoseconds", 1e9: "seconds vs nanoseconds"}


@dataclass(frozen=True)
class PoseSamples:
    """Poses at K query stamps; rows where ``valid`` is False hold NaN."""

    positions: NDArray[np.float64]
    quaternions: NDArray[np.float64]
    offset_s: NDArray[np.float64]
    angular_rate: NDArray[np.float64]
    valid: NDArray[np.bool_]
    outside: NDArray[np.bool_]
    in_gap: NDArray[np.bool_]


@dataclass(frozen=True)
class PoseTrack:
    """Time-sorted body poses: int64 ns ``stamps``, ``positions`` (M, 3), ``quaternions`` (M, 4)."""

    stamps: NDArray[np.int64]
    positions: NDArray[np.float64]
    quaternions: NDArray[np.float64]
    source: str = "poses"
    duplicates: int = 0
    reordered: int = 0

    def __len__(self) -> int:
        return int(self.stamps.shape[0])

    @classmethod
    def from_samples(
        cls, stamps: ArrayLike, positions: ArrayLike, quats: ArrayLike, source: str = "poses"
    ) -> PoseTrack:
        """Sort, de-duplicate and check raw samples; ``source`` names them in errors.

        Zero or non-finite quaternions are errors; non-unit ones are normalized
        (with a warning when off by more than 1e-3) and signs are made continuous
        so interpolation never takes the long way round.
        """
        t, p, q = _as_arrays(stamps, positions, quats, source)
        norms = np.linalg.norm(q, axis=1)
        bad = ~np.isfinite(norms) | (norms < 1e-9) | ~np.isfinite(p).all(axis=1)
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            raise PoseError(
                f"{source}: sample {i} (stamp {int(t[i])} ns) has an unusable pose "
                f"position={p[i].tolist()} quaternion={q[i].tolist()}"
            )
        off = np.abs(norms - 1.0)
        if (off > 1e-3).any():
            warnings.warn(
                f"{source}: {int((off > 1e-3).sum())} quaternions are not unit "
                f"(worst norm {norms[np.argmax(off)]:.6g}); normalized",
                stacklevel=2,
            )
        fix = off > 1e-12
        q[fix] /= norms[fix, None]
        reordered = int(np.count_nonzero(np.diff(t) < 0))
        order = np.argsort(t, kind="stable")
        t, p, q = t[order], p[order], q[order]
        keep = np.concatenate([[True], np.diff(t) != 0])
        t, p, q = t[keep], p[keep], q[keep]
        dots = np.einsum("ij,ij->i", q[1:], q[:-1])
        signs = np.cumprod(np.where(dots < 0, -1.0, 1.0))
        q[1:] *= signs[:, None]
        dup = int(keep.size - np.count_nonzero(keep))
        return cls(t, p, q, source, dup, reordered)

    def check_units(self, stamps_ns: ArrayLike) -> None:
        """Raise :class:`PoseError` when ``stamps_ns`` look like a different unit from the track."""
        s = np.asarray(stamps_ns, dtype=np.int64).reshape(-1)
        if s.size == 0 or ((s >= self.stamps[0]) & (s <= self.stamps[-1])).any():
            return
        ratio = float(np.abs(s).max()) / max(float(np.abs(self.stamps).max()), 1.0)
        for factor, what in _UNIT_FACTORS.items():
            for r, bigger in ((ratio, "scan"), (1.0 / max(ratio, 1e-300), "pose")):
                if factor / 3.0 < r < factor * 3.0:
                    raise PoseError(
                        f"{self.source}: {bigger} stamps are ~{factor:.0e} times larger than the "
                        f"others (scans near {int(s.max())} ns, poses {int(self.stamps[0])}.."
                        f"{int(self.stamps[-1])} ns): wrong stamp unit ({what})?"
                    )

    def interpolate(self, stamps_ns: ArrayLike, max_gap_s: float = 0.5) -> PoseSamples:
        """Poses at ``stamps_ns``: linear position, slerp attitude, never extrapolated.

        Stamps outside [first, last] sample are ``outside``; stamps between two
        samples more than ``max_gap_s`` apart are ``in_gap`` (an exact sample hit
        is always valid). ``offset_s`` is the time to the nearest sample and
        ``angular_rate`` the rotation rate (rad/s) between the bracketing samples.
        """
        s = np.asarray(stamps_ns, dtype=np.int64).reshape(-1)
        self.check_units(s)
        t = self.stamps
        right = np.searchsorted(t, s, side="right")
        hit = (right > 0) & (t[np.maximum(right - 1, 0)] == s)
        outside = ((s < t[0]) | (s > t[-1])) & ~hit
        nearest = np.minimum(
            np.abs(s - t[np.clip(right - 1, 0, len(t) - 1)]),
            np.abs(t[np.clip(right, 0, len(t) - 1)] - s),
        )
        if len(t) == 1:
            rate, span = np.zeros(s.size), np.zeros(s.size, dtype=np.int64)
        else:
            i0 = np.clip(right - 1, 0, len(t) - 2)
            span = t[i0 + 1] - t[i0]
            rate = self._rates[i0]
        in_gap = ~outside & ~hit & (span > max_gap_s * _NS)
        valid = ~outside & ~in_gap
        pos, quat = self._at(s, valid, hit, right)
        return PoseSamples(pos, quat, nearest / _NS, rate, valid, outside, in_gap)

    @cached_property
    def _rates(self) -> NDArray[np.float64]:
        """Rotation rate (rad/s) between each sample and the next (once per track: a
        stream asks for one scan's pose at a time)."""
        q = self.quaternions
        rel = Rotation.from_quat(q[:-1]).inv() * Rotation.from_quat(q[1:])
        rates: NDArray[np.float64] = np.linalg.norm(rel.as_rotvec(), axis=1) / (
            np.diff(self.stamps) / _NS)
        return rates

    @cached_property
    def _slerp(self) -> Slerp:
        """Slerp over the track, times in ns since the first sample (exact below 104 days)."""
        return Slerp(
            (self.stamps - self.stamps[0]).astype(np.float64), Rotation.from_quat(self.quaternions)
        )

    def _at(
        self, s: NDArray[np.int64], valid: NDArray[np.bool_], hit: NDArray[np.bool_],
        right: NDArray[np.intp]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Positions and quaternions at valid stamps (exact samples on hits), NaN elsewhere."""
        pos = np.full((s.size, 3), np.nan)
        quat = np.full((s.size, 4), np.nan)
        exact = valid & hit
        pos[exact] = self.positions[right[exact] - 1]
        quat[exact] = self.quaternions[right[exact] - 1]
        between = valid & ~hit
        if between.any():
            t, j = self.stamps, right[between]
            alpha = (s[between] - t[j - 1]) / (t[j] - t[j - 1])
            pos[between] = self.positions[j - 1] + alpha[:, None] * (
                self.positions[j] - self.positions[j - 1]
            )
            q = self._slerp((s[between] - t[0]).astype(np.float64)).as_quat()
            flip = np.einsum("ij,ij->i", q, self.quaternions[j - 1]) < 0
            q[flip] *= -1.0
            quat[between] = q
        return pos, quat


def _as_arrays(
    stamps: ArrayLike, positions: ArrayLike, quats: ArrayLike, source: str
) -> tuple[NDArray[np.int64], NDArray[np.float64], NDArray[np.float64]]:
    """Copies of the inputs as int64 (M,), float64 (M, 3) and (M, 4), shape-checked."""
    t = np.array(stamps, dtype=np.int64).reshape(-1)
    p = np.array(positions, dtype=np.float64)
    q = np.array(quats, dtype=np.float64)
    if t.size == 0:
        raise PoseError(f"{source}: no pose samples")
    if p.shape != (t.size, 3) or q.shape != (t.size, 4):
        raise PoseError(
            f"{source}: expected {t.size} positions (M, 3) and quaternions (M, 4), "
            f"got {p.shape} and {q.shape}"
        )
    return t, p, q


def header_stamp(header: HeaderMsg, log_time: int) -> int:
    """Header stamp in ns, or the log time when the header stamp is zero."""
    ns = int(header.stamp.sec) * _NS + int(header.stamp.nanosec)
    return ns if ns else int(log_time)


def _pose_values(pose: PoseMsg) -> tuple[float, ...]:
    p, o = pose.position, pose.orientation
    return (p.x, p.y, p.z, o.x, o.y, o.z, o.w)


def _transform_record(tf: TransformStampedMsg, log_time: int) -> PoseRecord:
    t, r = tf.transform.translation, tf.transform.rotation
    return PoseRecord(tf.header.frame_id, tf.child_frame_id, header_stamp(tf.header, log_time),
                      (t.x, t.y, t.z, r.x, r.y, r.z, r.w))


def pose_records(msg: object, msgtype: str, log_time: int) -> list[PoseRecord]:
    """``(parent, child, stamp_ns, (x, y, z, qx, qy, qz, qw))`` for each pose in ``msg``.

    ``msgtype`` (the bag connection's) says which of :data:`POSE_TYPES` ``msg`` is, as
    rosbags built it from that definition. PoseStamped has no child frame (``""``); a
    TFMessage yields one record per transform.
    """
    if msgtype == "geometry_msgs/msg/PoseStamped":
        stamped = cast(PoseStampedMsg, msg)
        header = stamped.header
        return [PoseRecord(header.frame_id, "", header_stamp(header, log_time),
                           _pose_values(stamped.pose))]
    if msgtype == "nav_msgs/msg/Odometry":
        odom = cast(OdometryMsg, msg)
        header = odom.header
        return [PoseRecord(header.frame_id, odom.child_frame_id, header_stamp(header, log_time),
                           _pose_values(odom.pose.pose))]
    if msgtype == "tf2_msgs/msg/TFMessage":
        return [_transform_record(tf, log_time) for tf in cast(TFMessageMsg, msg).transforms]
    raise PoseError(f"message type {msgtype} carries no pose (expected one of {POSE_TYPES})")


def select_tf_child(
    records: list[PoseRecord], sensor: str | None, body: str | None, source: str
) -> str:
    """The body frame among the child frames of ``/tf`` records.

    ``body`` (from ``/tf_static`` or the caller) wins when present; otherwise the
    only child frame that is neither the sensor nor the parent of another
    non-sensor transform (the leaf of ``map -> odom -> base_link``).
    """
    children = sorted({r[1] for r in records})
    if body:
        if body not in children:
            raise PoseError(f"{source}: no transform to body frame {body!r} (children: {children})")
        return body
    parents = {r[0] for r in records if r[1] != sensor}
    leaves = [c for c in children if c != sensor and c not in parents]
    if len(leaves) != 1:
        raise PoseError(
            f"{source}: cannot tell the body frame among the child frames {children} "
            f"(sensor {sensor!r}); publish /tf_static body -> sensor or pass body_frame"
        )
    return leaves[0]
