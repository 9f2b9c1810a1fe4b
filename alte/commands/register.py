"""``alte register``: a bag's LiDAR frames -> one inertial point cloud file (thesis 2.1.3)."""

from __future__ import annotations

import argparse
from pathlib import Path

from alte.errors import ParameterError, PointFileError
from alte.fsutil import refuse_overwrite
from alte.io.bag import read_frames
from alte.io.pointfiles import WRITE_SUFFIXES, write_points
from alte.registration import Registration, check_options, register
from alte.types import Mount

__all__ = ["add_parser", "format_counts", "parse_box", "run"]


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register ``alte register``."""
    p = subparsers.add_parser(
        "register", help="register a bag's scans into one inertial point cloud",
        description="Transform every scan of BAG into the inertial frame with the pose at its "
                    "stamp (thesis eq. 2.2), drop fast-manoeuvre frames, crop to the control "
                    "volume, grid-average down-sample, merge, and write the cloud. Values that "
                    "start with '-' need '=': --crop=-5,-5,-1,5,5,3.")
    p.add_argument("bag", type=Path, help="ROS 1 .bag file or ROS 2 bag folder")
    p.add_argument("--out", type=Path, required=True,
                   help="output cloud: .ply, .pcd, .npz, .las, .laz, .xyz")
    p.add_argument("--voxel", type=float, default=None, metavar="M",
                   help="grid-average / box-grid merge cell size in metres (default: keep all)")
    p.add_argument("--crop", default=None, metavar="XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX",
                   help="control volume in inertial metres; points outside are dropped")
    p.add_argument("--mount", default=None, metavar="X,Y,Z,ROLL,PITCH,YAW",
                   help="sensor offset (m) and rotation (deg) on the body (default: the bag's)")
    p.add_argument("--cloud-topic", default=None, help="PointCloud2 / VelodyneScan topic")
    p.add_argument("--pose-topic", default=None, help="pose / odometry / TF topic")
    p.add_argument("--no-pose", action="store_true",
                   help="ignore poses: identity body pose for every scan (static sensor)")
    p.add_argument("--max-rate", type=float, default=None, metavar="RAD_S",
                   help="drop frames whose body angular rate exceeds this (rad/s)")
    p.add_argument("--max-offset", type=float, default=None, metavar="S",
                   help="drop frames whose nearest pose is further than this in time (s)")
    p.add_argument("--force", action="store_true", help="overwrite --out if it exists")
    p.set_defaults(func=run)


def parse_box(text: str) -> tuple[float, ...]:
    """Parse ``xmin,ymin,zmin,xmax,ymax,zmax`` for ``--crop``."""
    try:
        values = tuple(float(v) for v in text.split(","))
    except ValueError as err:
        raise ParameterError(f"--crop {text!r}: expected 6 numbers xmin,...,zmax") from err
    if len(values) != 6:
        raise ParameterError(f"--crop {text!r}: expected 6 numbers xmin,...,zmax")
    return values


def format_counts(counts: dict[str, int]) -> list[str]:
    """Human summary of what went in, was dropped and why, and came out."""
    c = counts
    return [
        f"frames: {c['frames_in']} in, {c['frames_kept']} kept; dropped "
        f"{c['frames_dropped_rate']} (angular rate), {c['frames_dropped_offset']} (pose offset), "
        f"{c['frames_dropped_empty']} (no points left)",
        f"points: {c['points_in']} in; dropped {c['points_dropped_nonfinite']} (NaN/inf), "
        f"{c['points_dropped_crop']} (outside crop box); {c['points_registered']} after "
        f"per-frame down-sampling, {c['points_out']} out",
    ]


def _reader_line(reader_counts: dict[str, int]) -> str:
    parts = ", ".join(f"{k.replace('_', ' ')} {v}" for k, v in reader_counts.items())
    return f"bag: {parts}" if parts else "bag: read"


def run(args: argparse.Namespace) -> int:
    """Read, register, write; print the counts."""
    if args.out.suffix.lower() not in WRITE_SUFFIXES:
        raise PointFileError(f"--out {args.out}: unknown point file type; use {WRITE_SUFFIXES}")
    refuse_overwrite(args.out, args.force)  # fail before the long read
    mount = Mount.from_string(args.mount) if args.mount else None
    box = parse_box(args.crop) if args.crop else None
    check_options(args.voxel, box, args.max_rate, args.max_offset)
    if args.no_pose and args.pose_topic:
        raise ParameterError("--no-pose and --pose-topic exclude each other")
    frameset = read_frames(
        args.bag, cloud_topic=args.cloud_topic, pose_topic="" if args.no_pose else args.pose_topic,
        mount=mount, allow_no_pose=args.no_pose, progress=True,
    )
    result: Registration = register(
        frameset.frames, frameset.mount, voxel=args.voxel, crop_box=box,
        max_rate=args.max_rate, max_offset=args.max_offset, progress=True,
    )
    write_points(args.out, result.points, overwrite=args.force)
    print(_reader_line(dict(frameset.counts)))
    for line in format_counts(result.counts):
        print(line)
    print(f"wrote {len(result.points)} points to {args.out}")
    return 0
