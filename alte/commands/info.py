"""``alte info BAG``: topics, message counts, duration and the cloud/pose topics alte would use."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from alte.io.bag import BagInfo, inspect_bag

__all__ = ["add_parser", "format_info", "run"]


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register ``alte info``."""
    p = subparsers.add_parser(
        "info",
        help="show a bag's topics and the cloud/pose topics alte detects",
        description="List the topics of BAG (ROS 1 .bag file or ROS 2 bag folder) with their "
        "types and message counts, the duration, the detected cloud and pose topics and the "
        "/tf_static sensor mount.",
    )
    p.add_argument("bag", type=Path, help="ROS 1 .bag file or ROS 2 bag folder")
    p.add_argument("--json", action="store_true", help="print one JSON object instead of text")
    p.add_argument("--cloud-topic", default=None, help="PointCloud2 / VelodyneScan topic")
    p.add_argument("--pose-topic", default=None, help="pose / odometry / TF topic")
    p.set_defaults(func=run)


def format_info(info: BagInfo) -> list[str]:
    """Human-readable lines for :func:`run`."""
    width = max((len(name) for name in info.topics), default=0)
    lines = [f"bag:       {info.path}", f"duration:  {info.duration_s:.3f} s", "topics:"]
    lines += [
        f"  {name:<{width}}  {count:>8}  {msgtype}"
        for name, (msgtype, count) in info.topics.items()
    ]
    lines.append(f"cloud:     {info.cloud_topic or '-'} ({info.frames} scans)")
    lines.append(f"pose:      {info.pose_topic or '-'}")
    if info.mount is not None:
        lines.append(f"mount:     {info.mount.to_string()} (x,y,z m, roll,pitch,yaw deg)")
    lines += [f"note:      {note}" for note in info.notes]
    return lines


def run(args: argparse.Namespace) -> int:
    """Inspect the bag and print the summary."""
    info = inspect_bag(args.bag, cloud_topic=args.cloud_topic, pose_topic=args.pose_topic)
    if args.json:
        print(json.dumps(info.to_dict(), sort_keys=True))
    else:
        print("\n".join(format_info(info)))
    return 0
