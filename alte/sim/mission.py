"""Fly (or push) one terrain's mission: poses -> rays -> scans and the pose stream.

Pure arrays, no files. Scans are taken at 10 Hz along the whole mission; with
``frames=N`` an evenly spaced subset of the same scans is simulated (same path,
speeds and dynamics, fewer scans), and every scan draws its noise from its own
``SeedSequence(seed, spawn_key=(terrain, 0, scan index))`` stream, so a scan's
points do not depend on ``frames`` or on which other terrains were simulated.
Experimental cases stamp each scan ``time_offset_s`` + N(0, ``jitter_s``) earlier
than it was really taken, the desynchronization of thesis fig. 4.34.

A :class:`~alte.sim.profile.SensorProfile` other than the thesis' adds what a real sensor
does (per-point time and the sweep in motion, the IMU, a faster pose topic, dropouts,
mixed pixels); each draws from its own stream (3 = dropouts, 4 = IMU), so the thesis'
noise is the same under every profile.
"""

from __future__ import annotations

import zlib
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from alte.errors import ParameterError
from alte.progress import bar as progress_bar
from alte.sim.imu import ImuStream, imu_stream
from alte.sim.platform import Cart, Trajectory, mocap_stream
from alte.sim.profile import SensorProfile
from alte.sim.returns import BEAM_DIVERGENCE_MRAD, lost_returns, mixed_distance
from alte.sim.scene import CLASSES
from alte.sim.sensor import VLP16, Hits, cast, cast_sweep, measure
from alte.sim.terrains import Terrain
from alte.types import Mount

__all__ = ["START_NS", "Simulation", "TruePoses", "scan_indices", "simulate", "true_poses"]

#: Stamp of the mission start (2023-11-14T22:13:20Z), fixed for byte-identical bags.
START_NS = 1_700_000_000_000_000_000
_SCAN_PHASE_NS = 53_000_000
_BATCH = 48


@dataclass(frozen=True, eq=False)
class Simulation:
    """Simulated scans (sensor frame) with their stamps, and the pose stream of the body.

    ``times`` holds each scan's per-point time (s from its stamp) for a swept sensor,
    ``imu`` the IMU samples when the profile has an IMU.
    """

    stamps: NDArray[np.int64]
    scans: list[NDArray[np.float64]]
    scan_index: NDArray[np.int64]
    pose_stamps: NDArray[np.int64]
    positions: NDArray[np.float64]
    quaternions: NDArray[np.float64]
    mount: Mount
    counts: dict[str, int]
    duration_s: float
    times: list[NDArray[np.float64]] | None = None
    imu: ImuStream | None = None
    profile: SensorProfile = field(default_factory=SensorProfile)


def scan_indices(total: int, frames: int | None) -> NDArray[np.int64]:
    """Indices of the simulated scans among the mission's ``total`` (evenly spaced)."""
    if frames is None:
        return np.arange(total)
    if isinstance(frames, bool) or not isinstance(frames, int | np.integer) or frames < 1:
        raise ParameterError(f"frames={frames!r}: expected a positive integer or None")
    if frames > total:
        raise ParameterError(f"frames={frames} exceeds the mission's {total} scans")
    return np.unique(np.round(np.linspace(0, total - 1, frames)).astype(np.int64))


def _rng(seed: int, name: str, *stream: int) -> np.random.Generator:
    """Generator of ``stream`` (0 = scan noise, 1 = desync, 2 = motion capture) of a terrain."""
    if isinstance(seed, bool) or not isinstance(seed, int | np.integer) or seed < 0:
        raise ParameterError(f"seed={seed!r}: expected a non-negative integer")
    key = zlib.crc32(name.encode())
    return np.random.default_rng(np.random.SeedSequence(int(seed), spawn_key=(key, *stream)))


def _acquisition_times(terrain: Terrain, seed: int, stamps_s: NDArray[np.float64],
                       index: NDArray[np.int64]) -> NDArray[np.float64]:
    """True scan times: the stamps, late by the pose/scan offset and jitter (cart only)."""
    platform = terrain.spec.platform
    if not isinstance(platform, Cart):
        return stamps_s
    rng = _rng(seed, terrain.spec.name, 1)
    jitter = rng.normal(0.0, platform.jitter_s, terrain.spec.frames)[index]
    late: NDArray[np.float64] = stamps_s + platform.time_offset_s + jitter
    return late


def _pose_stream(terrain: Terrain, traj: Trajectory, seed: int, stamps: NDArray[np.int64],
                 pose_hz: float = 0.0
                 ) -> tuple[NDArray[np.int64], NDArray[np.float64], NDArray[np.float64]]:
    """Gazebo's true state at the scan stamps (or at ``pose_hz``), or 100 Hz motion
    capture (cart)."""
    platform = terrain.spec.platform
    if not isinstance(platform, Cart):
        if pose_hz > 0:
            step = round(1e9 / pose_hz)
            stamps = START_NS + step * np.arange(int((traj.duration + 0.1) * 1e9) // step + 1)
        pos, rot = traj.pose((stamps - START_NS) / 1e9)
        return stamps.astype(np.int64), pos, rot.as_quat(canonical=False)
    step = round(1e9 / platform.mocap_hz)
    pose_stamps = START_NS + step * np.arange(int((traj.duration + 0.1) * 1e9) // step + 1)
    rng = _rng(seed, terrain.spec.name, 2)
    pos, quat = mocap_stream(traj, (pose_stamps - START_NS) / 1e9, platform, rng)
    return pose_stamps.astype(np.int64), pos, quat


@dataclass(frozen=True, eq=False)
class TruePoses:
    """The body's true pose when each scan was taken, keyed by the scan's (bag) stamp.

    For the experimental cases the scan stamps are early (desynchronization), so these
    differ from the recorded pose stream interpolated at the stamps; this is the truth
    a pose estimate (odometry, refinement) is scored against.
    """

    stamps: NDArray[np.int64]
    positions: NDArray[np.float64]
    quaternions: NDArray[np.float64]


def _mission(terrain: Terrain, seed: int, frames: int | None, sensor: VLP16
             ) -> tuple[NDArray[np.int64], NDArray[np.int64], Trajectory, NDArray[np.float64]]:
    """Scan indices, stamps, trajectory and true acquisition times (s from start)."""
    _rng(seed, terrain.spec.name)  # validates the seed
    index = scan_indices(terrain.spec.frames, frames)
    period = round(1e9 / sensor.rate_hz)
    stamps = START_NS + _SCAN_PHASE_NS + period * index
    traj = Trajectory(terrain.spec.platform, terrain.spec.frames * period / 1e9)
    acq = _acquisition_times(terrain, seed, (stamps - START_NS) / 1e9, index)
    return index, stamps, traj, acq


def true_poses(terrain: Terrain, seed: int = 0, frames: int | None = None,
               sensor: VLP16 | None = None) -> TruePoses:
    """True body poses at every simulated scan of ``simulate(terrain, seed, frames)``."""
    _, stamps, traj, acq = _mission(terrain, seed, frames, sensor or VLP16())
    pos, rot = traj.pose(acq)
    return TruePoses(stamps.astype(np.int64), pos, rot.as_quat(canonical=False))


def simulate(terrain: Terrain, seed: int = 0, frames: int | None = None,
             sensor: VLP16 | None = None, *, progress: bool = False,
             profile: SensorProfile | None = None) -> Simulation:
    """Simulate ``terrain``'s mission (all scans, or ``frames`` evenly spaced ones)."""
    sensor, profile = sensor or VLP16(), profile or SensorProfile()
    spec = terrain.spec
    index, stamps, traj, acq = _mission(terrain, seed, frames, sensor)
    caster = _Caster(terrain, traj, sensor, profile)
    scans: list[NDArray[np.float64]] = []
    times: list[NDArray[np.float64]] = []
    counts: dict[str, int] = {}
    for lo in progress_bar(range(0, len(index), _BATCH), desc=spec.name, unit="batch",
                   disable=not progress):
        sl = slice(lo, lo + _BATCH)
        hits = caster.hits(acq[sl])
        ranges, part = measure(hits, sensor, [_rng(seed, spec.name, 0, int(i)) for i in index[sl]])
        if profile.dropout:
            lost = lost_returns(hits, caster.class_ids, profile,
                                [_rng(seed, spec.name, 3, int(i)) for i in index[sl]])
            part["dropout"] = int((lost & np.isfinite(ranges)).sum())
            part["returns"] -= part["dropout"]
            ranges[lost] = np.nan
        valid = np.isfinite(ranges)
        scans += [caster.directions[v] * r[v, None] for v, r in zip(valid, ranges, strict=True)]
        times += [caster.ray_times[v] for v in valid]
        part.update(_class_counts(caster.class_ids[hits.triangle[valid]]))
        counts = {k: counts.get(k, 0) + part.get(k, 0) for k in {*counts, *part}}
    pose_stamps, positions, quats = _pose_stream(terrain, traj, seed, stamps, profile.pose_hz)
    imu = imu_stream(traj, START_NS, profile, _rng(seed, spec.name, 4)) if profile.imu_hz else None
    counts["frames"], counts["poses"] = len(index), len(pose_stamps)
    if imu is not None:
        counts["imu"] = len(imu)
    return Simulation(stamps.astype(np.int64), scans, index, pose_stamps, positions, quats,
                      spec.mount, dict(sorted(counts.items())), traj.duration,
                      times if profile.sweep else None, imu, profile)


class _Caster:
    """Casts a batch of scans as the profile says: one pose a scan (the thesis) or one
    pose a firing sequence (sweep); with mixed pixels, two more sub-rays a beam."""

    def __init__(self, terrain: Terrain, traj: Trajectory, sensor: VLP16,
                 profile: SensorProfile) -> None:
        self.traj, self.mount, self.profile = traj, terrain.spec.mount, profile
        self.directions = sensor.directions()
        half = np.degrees(BEAM_DIVERGENCE_MRAD / 2e3)
        self.sub_rays = [sensor.directions(-half), sensor.directions(half)]
        self.raycaster = terrain.scene.raycaster()
        self.class_ids = terrain.scene.class_ids
        self.group_times, self.ray_times = sensor.firing_times()

    def hits(self, acq: NDArray[np.float64]) -> Hits:
        """Hits (K, M) of the scans taken at ``acq`` (s from the mission start)."""
        t = (acq[:, None] + self.group_times[None, :]).reshape(-1) if self.profile.sweep \
            else acq
        body_pos, body_rot = self.traj.pose(t)
        pos = body_pos + body_rot.apply(self.mount.translation)
        rot = body_rot * self.mount.rotation
        if self.profile.sweep:
            pos = pos.reshape(len(acq), -1, 3)
        centre = self._shoot(pos, rot, self.directions)
        if not self.profile.mixed_pixels:
            return centre
        left, right = (self._shoot(pos, rot, d) for d in self.sub_rays)
        return mixed_distance(centre, left, right, self.profile)

    def _shoot(self, pos: NDArray[np.float64], rot: Rotation[tuple[int, ...]],
               directions: NDArray[np.float64]) -> Hits:
        if self.profile.sweep:
            return cast_sweep(self.raycaster, pos, rot, directions)
        return cast(self.raycaster, pos, rot, directions)


def _class_counts(class_ids: NDArray[np.uint8]) -> dict[str, int]:
    """Returns per object class, keyed ``returns_<class>``."""
    per = np.bincount(class_ids, minlength=len(CLASSES))
    return {f"returns_{c}": int(n) for c, n in zip(CLASSES, per, strict=True) if n}
