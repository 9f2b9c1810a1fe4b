"""Input/output: ROS bags -> posed frames, bags from frames, point files, raw Velodyne packets.

``read_frames`` is the pipeline's entry point (bag -> frames); ``write_bag`` /
``write_frames`` write ROS 2 bags the simulator and tests read back.
"""

from __future__ import annotations

from alte.io.bag import FrameSet, read_frames
from alte.io.baginfo import BagInfo, inspect_bag
from alte.io.pointcloud2 import decode_pointcloud2, encode_pointcloud2
from alte.io.pointfiles import read_points, write_points
from alte.io.pose import PoseSamples, PoseTrack
from alte.io.velodyne import decode_velodyne_scan, register_velodyne_types
from alte.io.writer import write_bag, write_frames

__all__ = [
    "BagInfo",
    "FrameSet",
    "PoseSamples",
    "PoseTrack",
    "decode_pointcloud2",
    "decode_velodyne_scan",
    "encode_pointcloud2",
    "inspect_bag",
    "read_frames",
    "read_points",
    "register_velodyne_types",
    "write_bag",
    "write_frames",
    "write_points",
]
