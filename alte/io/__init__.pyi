from .bag import FrameSet, read_frames
from .baginfo import BagInfo, inspect_bag
from .pointcloud2 import decode_pointcloud2, encode_pointcloud2
from .pointfiles import read_points, write_points
from .pose import PoseSamples, PoseTrack
from .velodyne import decode_velodyne_scan, register_velodyne_types
from .writer import write_bag, write_frames

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
