"""Simulated missions as bags without a pose topic (what odometry has to work from)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from rosbags.typesys import Stores, get_typestore

from alte.io.bags.pointcloud2 import encode_pointcloud2, make_header
from alte.sim import Simulation, TruePoses, get_terrain, mission, simulate, true_poses
from alte.sim.imu import ImuStream
from alte.sim.profile import SensorProfile
from alte.sim.scenario import write_scenario
from alte.sim.terrains import Terrain
from support.bagtools import write_ros2

__all__ = ["first_scans", "first_scans_folder", "simulate_scans", "unposed_bag"]

_TS = get_typestore(Stores.ROS2_HUMBLE)


def simulate_scans(terrain: Terrain, indices: Sequence[int], seed: int = 0, *,
                   profile: SensorProfile | None = None) -> Simulation:
    """The scans ``indices`` of ``terrain``'s mission, and no other, each as the whole
    mission simulates it (every scan draws its own noise stream: the same arrays).
    ``simulate(frames=N)`` spreads N scans over the whole mission; a test that needs the
    first scans, or a denser stretch, would otherwise simulate every scan of it. The
    mission's choice of scans (``alte.sim.mission.scan_indices``) is replaced for the call."""
    chosen = np.asarray(indices, dtype=np.int64)
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(mission, "scan_indices", lambda total, frames: chosen)
        return simulate(terrain, seed, len(chosen), profile=profile)


def first_scans(name: str, count: int, seed: int = 0) -> tuple[Simulation, TruePoses]:
    """The first ``count`` scans of terrain ``name``'s 10 Hz mission (the whole mission's
    scans, see :func:`simulate_scans`) and their true poses."""
    terrain = get_terrain(name)
    sim = simulate_scans(terrain, range(count), seed)
    truth = true_poses(terrain, seed)
    keep = slice(0, count)
    return sim, TruePoses(truth.stamps[keep], truth.positions[keep], truth.quaternions[keep])


def first_scans_folder(target: Path, name: str, count: int, *,
                       profile: SensorProfile | None = None, seed: int = 0) -> Path:
    """A terrain folder (bag, ground truth, scenario.json) of the first ``count``
    consecutive scans of terrain ``name``'s mission, each as the whole mission simulates
    it (its own noise stream), the IMU (a profile's) over the whole mission.

    ``simulate(frames=N)`` spreads N scans over the mission, and odometry over those
    integrates the IMU across the gaps (4 scans of sim_lan_1: 45 s at 200 Hz, 5 CPU s a
    LIO run, against 1 s over 4 consecutive ones); the whole mission costs a simulation
    of every scan. The IMU ends a second after the last scan (reading the whole
    mission's took a LIO run another second). ``target`` is this folder alone:
    ``ensure_terrain`` would take its scenario.json for ``frames=count`` evenly spaced."""
    terrain = get_terrain(name)
    sim = simulate_scans(terrain, range(count), seed, profile=profile)
    if sim.imu is not None:
        sim = replace(sim, imu=_until(sim.imu, int(sim.stamps[-1]) + 1_000_000_000))
    return write_scenario(target, terrain, sim, seed=seed, frames=count)


def _until(imu: ImuStream, stamp: int) -> ImuStream:
    """The samples of ``imu`` up to ``stamp`` (ns)."""
    keep = imu.stamps <= stamp
    return replace(imu, stamps=imu.stamps[keep], angular_velocity=imu.angular_velocity[keep],
                   linear_acceleration=imu.linear_acceleration[keep],
                   gyro_bias=imu.gyro_bias[keep], accel_bias=imu.accel_bias[keep])


def unposed_bag(path: Path, sim: Simulation, count: int) -> Path:
    """The first ``count`` scans of ``sim`` on /velodyne_points plus the /tf_static mount."""
    types = _TS.types
    first = int(sim.stamps[0])
    tf = types["geometry_msgs/msg/TransformStamped"](
        header=make_header(first, "base_link", _TS), child_frame_id="velodyne",
        transform=types["geometry_msgs/msg/Transform"](
            types["geometry_msgs/msg/Vector3"](*map(float, sim.mount.translation)),
            types["geometry_msgs/msg/Quaternion"](*map(float, sim.mount.quaternion))))
    messages = [("/tf_static", "tf2_msgs/msg/TFMessage", first,
                 types["tf2_msgs/msg/TFMessage"](transforms=[tf]))]
    messages += [("/velodyne_points", "sensor_msgs/msg/PointCloud2", int(stamp),
                  encode_pointcloud2(np.asarray(scan), int(stamp), "velodyne", _TS))
                 for stamp, scan in zip(sim.stamps[:count], sim.scans[:count], strict=True)]
    return write_ros2(path, messages)
