"""Simulated missions as bags without a pose topic (what odometry has to work from)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from rosbags.typesys import Stores, get_typestore

from alte.io.bags.pointcloud2 import encode_pointcloud2, make_header
from alte.sim import Simulation, TruePoses, get_terrain, simulate, true_poses
from support.bagtools import write_ros2

__all__ = ["first_scans", "unposed_bag"]

_TS = get_typestore(Stores.ROS2_HUMBLE)


def first_scans(name: str, count: int, seed: int = 0) -> tuple[Simulation, TruePoses]:
    """The whole 10 Hz mission of terrain ``name`` and its true poses (first ``count``)."""
    terrain = get_terrain(name)
    sim = simulate(terrain, seed)
    truth = true_poses(terrain, seed)
    keep = slice(0, count)
    return sim, TruePoses(truth.stamps[keep], truth.positions[keep], truth.quaternions[keep])


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
