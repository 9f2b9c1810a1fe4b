from .bags.bag import FrameSet, read_frames
from .bags.baginfo import BagInfo, inspect_bag
from .bags.pointcloud2 import decode_pointcloud2, encode_pointcloud2
from .bags.velodyne import decode_velodyne_scan, register_velodyne_types
from .bags.writer import write_bag, write_frames
from .points.pointfiles import read_points, write_points
from .poses.pose import PoseSamples, PoseTrack

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
