"""``alte export INPUT --mcap FILE --mapper M``: a map run as one ROS 2 MCAP file.

Open the file in Foxglove Studio, or play it into RViz (``ros2 bag play FILE``); the
topics and their types are listed in :mod:`alte.export.mcap` and in the documentation's
Foxglove / RViz guide (docs/how-to/foxglove-rviz.md). The final map is there from the
file's first instant; with ``--timeline N`` it is also written every N mapped scans,
stamped with the scan's time, so scrubbing the timeline replays the mapping.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from alte.commands.map import add_map_options, export_options, mapped, print_summary
from alte.commands.options import add_frame_options

__all__ = ["add_parser", "run"]


def add_parser(subparsers: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register ``alte export``."""
    p = subparsers.add_parser(
        "export", help="map an input and write the result as a ROS 2 MCAP (Foxglove, RViz)",
        description="Map INPUT as 'alte map' does and write one ROS 2 MCAP file: registered "
                    "cloud and scans (PointCloud2), trajectory (Path), pose (PoseStamped, "
                    "/tf), map cells (MarkerArray), occupancy for landing (OccupancyGrid: 0 "
                    "free, 100 occupied, -1 unseen; see --occupancy-set), height and "
                    "occupancy as a Foxglove grid (foxglove_msgs/Grid), 2D maps for RViz "
                    "(GridMap) and Octomap (octomap_msgs/Octomap). The final map, trajectory "
                    "and cloud are also written at the file's first instant, so a viewer "
                    "shows them on opening. An existing file is never replaced without "
                    "--force.")
    add_frame_options(p, origin=True)
    add_map_options(p)
    p.add_argument("--mcap", type=Path, required=True, metavar="FILE",
                   help="the MCAP file to write (.mcap)")
    p.add_argument("--all-cells", action="store_true",
                   help="draw free cells of 3D maps too (default: occupied cells only)")
    p.add_argument("--no-scans", action="store_true",
                   help="leave out the registered scans (/alte/scan): a smaller file")
    p.add_argument("--force", action="store_true", help="overwrite --mcap if it exists")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Map, write the MCAP, print the summary with the message count per topic."""
    options = export_options(args, args.mcap)
    result, topics = mapped(args, args.mcap, options)
    summary = result.summary()
    summary["mcap"] = {"file": str(args.mcap), "messages": topics}
    print_summary(summary, args.json)
    return 0
