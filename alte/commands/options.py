"""Command-line options shared by the commands that read an input (``register``, ``map``),
and a ground filter's ``--method`` / ``--set`` (``ground``; ``simulate`` as
``--ground-method`` / ``--ground-set``).

They map one to one onto :class:`alte.pipeline.FrameSettings` and the ground stage's settings
records; a bad value is a :class:`~alte.errors.ParameterError` naming the flag, raised
before any input is read.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from alte.commands.flags import flag_message
from alte.errors import ParameterError
from alte.ground.settings import (
    DEFAULT_METHOD,
    DEFAULT_SETTINGS,
    SOURCES,
    GroundSettings,
    ground_settings,
)
from alte.ground.settings import METHODS as GROUND_METHODS
from alte.params import key_values
from alte.pipeline import FrameSettings, PoseSource
from alte.registration.odometry import METHODS, OdometrySettings, odometry_params
from alte.types import Box, Mount

__all__ = ["add_frame_options", "add_ground_options", "add_odometry_options", "frame_spec",
           "ground_spec", "odometry_spec", "parse_box", "parse_key_values", "parse_origin"]

INPUT_HELP = ("ROS 1 .bag file or ROS 2 bag folder, a terrain folder made by 'alte simulate' "
              "(its control volume and voxel are used), or a point file")


def add_frame_options(p: argparse.ArgumentParser, *, origin: bool = False) -> None:
    """The flags that decide which frames are read and how they are registered."""
    p.add_argument("input", type=Path, help=INPUT_HELP)
    p.add_argument("--frames", type=int, default=None, metavar="N",
                   help="read at most N scans, evenly spaced over the recording")
    p.add_argument("--voxel", type=float, default=None, metavar="M",
                   help="grid-average / box-grid merge cell in metres (default: a terrain "
                        "folder's own, else keep every point)")
    p.add_argument("--crop", default=None, metavar="XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX",
                   help="control volume in inertial metres; points outside are dropped "
                        "(default: a terrain folder's own)")
    p.add_argument("--mount", default=None, metavar="X,Y,Z,ROLL,PITCH,YAW",
                   help="sensor offset (m) and rotation (deg) on the body (default: the bag's)")
    p.add_argument("--cloud-topic", default=None, help="PointCloud2 / VelodyneScan topic")
    p.add_argument("--pose-topic", default=None, help="pose / odometry / TF topic")
    p.add_argument("--pose-file", type=Path, default=None, metavar="FILE",
                   help="poses from a TUM file (t x y z qx qy qz qw per line) instead of a "
                        "pose topic")
    p.add_argument("--poses", choices=[s.value for s in PoseSource], default=None,
                   help="where scan poses come from: recorded (the pose topic), odometry "
                        "(LiDAR odometry, see --odometry), refine (recorded, aligned scan to "
                        "map where that is clearly better), identity (static sensor); "
                        "default: recorded, or odometry when the bag has no pose topic")
    add_odometry_options(p)
    p.add_argument("--no-deskew", action="store_true",
                   help="register each point where it was taken, even when the cloud has "
                        "per-point time (default: move it to the scan stamp with the "
                        "sensor's motion)")
    p.add_argument("--no-pose", action="store_true",
                   help="ignore poses: identity body pose for every scan (= --poses identity)")
    p.add_argument("--max-rate", type=float, default=None, metavar="RAD_S",
                   help="drop frames whose body angular rate exceeds this (rad/s)")
    p.add_argument("--max-offset", type=float, default=None, metavar="S",
                   help="drop frames whose nearest pose is further than this in time (s)")
    if origin:
        p.add_argument("--origin", default="0,0,0", metavar="X,Y,Z",
                       help="sensor position for a point file (default 0,0,0)")


def add_odometry_options(p: argparse.ArgumentParser) -> None:
    """``--odometry`` and ``--odometry-set`` (the backend and its settings)."""
    p.add_argument("--odometry", choices=METHODS, default=None,
                   help="odometry backend for --poses odometry: auto (the default: lio when "
                        "the bag has an IMU topic, else kiss), kiss (KISS-ICP), plane "
                        "(point-to-plane scan-to-map ICP) or lio (LiDAR-inertial: the bag's "
                        "IMU and the scans in one filter)")
    p.add_argument("--odometry-set", action="append", default=[], metavar="KEY=VALUE",
                   dest="odometry_sets",
                   help="odometry / refinement setting (repeatable), e.g. --odometry-set "
                        "voxel=0.5; the keys: " + "; ".join(
                            f"{k}: {v}" for k, v in OdometrySettings.help().items()
                            if k != "method"))


def parse_key_values(items: list[str], flag: str) -> dict[str, str]:
    """``["k=v", ...]`` -> ``{"k": "v"}`` (:func:`alte.params.key_values`); an error names
    ``flag``."""
    try:
        return key_values(items)
    except ParameterError as err:
        raise ParameterError(f"{flag} {err}") from err


def add_ground_options(p: argparse._ActionsContainer, prefix: str = "",
                       what: str = "the ground filter") -> None:
    """A ground filter's ``--{prefix}method`` and ``--{prefix}set`` (``what``: what naming
    the method does, leading its help)."""
    p.add_argument(f"--{prefix}method", choices=list(GROUND_METHODS), default=None,
                   help=f"{what}, with the method's published defaults; default: "
                        f"{DEFAULT_METHOD} with "
                        + ", ".join(f"{k}={v}" for k, v in DEFAULT_SETTINGS.as_dict().items())
                        + ", chosen on real "
                        "data. Sources: " + "; ".join(f"{k}: {v}" for k, v in SOURCES.items()))
    p.add_argument(f"--{prefix}set", action="append", default=[], metavar="KEY=VALUE",
                   dest=f"{prefix}sets".replace("-", "_"),
                   help=f"a setting of the method (repeatable; without --{prefix}method, of "
                        f"the default), e.g. --{prefix}set window=24; published defaults: "
                        + "; ".join(f"{name}: " + ", ".join(f"{k}={v}" for k, v in
                                                           cls().as_dict().items())
                                    for name, cls in GROUND_METHODS.items()))


def ground_spec(args: argparse.Namespace, prefix: str = "") -> tuple[str | None,
                                                                     GroundSettings]:
    """The method (None: not named) and settings of ``--{prefix}method`` /
    ``--{prefix}set``; errors name ``--{prefix}set``."""
    flag, key = f"--{prefix}set", prefix.replace("-", "_")
    method: str | None = getattr(args, f"{key}method")
    try:
        return method, ground_settings(method, parse_key_values(getattr(args, f"{key}sets"),
                                                                flag))
    except ParameterError as err:
        if str(err).startswith(flag):
            raise
        raise ParameterError(f"{flag}: {err}") from err


def odometry_spec(args: argparse.Namespace) -> OdometrySettings:
    """The :class:`OdometrySettings` of ``--odometry`` / ``--odometry-set`` (errors name them)."""
    settings = parse_key_values(getattr(args, "odometry_sets", []) or [], "--odometry-set")
    try:
        return odometry_params(getattr(args, "odometry", None), settings)
    except ParameterError as err:
        raise ParameterError(flag_message(err, {"--odometry", "--odometry-set"})) from err


def parse_box(text: str, flag: str = "--crop") -> Box:
    """``xmin,ymin,zmin,xmax,ymax,zmax`` -> :class:`~alte.types.Box`."""
    try:
        values = [float(v) for v in text.split(",")]
    except ValueError as err:
        raise ParameterError(f"{flag} {text!r}: expected 6 numbers xmin,...,zmax") from err
    if len(values) != 6:
        raise ParameterError(f"{flag} {text!r}: expected 6 numbers xmin,...,zmax")
    try:
        return Box.of(values)
    except ParameterError as err:
        raise ParameterError(f"{flag} {text!r}: {err}") from err


def parse_origin(text: str) -> tuple[float, float, float]:
    """``"x,y,z"`` -> a finite 3-tuple for ``--origin``."""
    try:
        values = np.array([float(v) for v in text.split(",")])
    except ValueError as err:
        raise ParameterError(f"--origin {text!r}: expected 3 numbers x,y,z") from err
    if values.shape != (3,) or not np.isfinite(values).all():
        raise ParameterError(f"--origin {text!r}: expected 3 finite numbers x,y,z")
    return (float(values[0]), float(values[1]), float(values[2]))


def _poses(args: argparse.Namespace) -> PoseSource:
    """``--poses`` (``--no-pose`` is ``--poses identity``); unset is ``auto``."""
    chosen = getattr(args, "poses", None)
    if args.no_pose and chosen not in (None, PoseSource.IDENTITY.value):
        raise ParameterError(f"--no-pose and --poses {chosen} exclude each other")
    if args.no_pose:
        return PoseSource.IDENTITY
    return PoseSource(chosen) if chosen else PoseSource.AUTO


def frame_spec(args: argparse.Namespace) -> FrameSettings:
    """The :class:`FrameSettings` of the parsed flags (its errors name the settings; the
    command line puts their flags in front, :mod:`alte.commands.flags`)."""
    poses = _poses(args)
    if poses is PoseSource.IDENTITY and args.pose_topic:
        raise ParameterError("--no-pose (--poses identity) and --pose-topic exclude each other")
    mount = Mount.from_string(args.mount) if args.mount else None
    odometry = odometry_spec(args)
    pose_file = getattr(args, "pose_file", None)
    if pose_file is not None and not pose_file.is_file():
        raise ParameterError(f"--pose-file {pose_file}: no such file")
    return FrameSettings(
        frames=args.frames, voxel=args.voxel,
        crop=parse_box(args.crop) if args.crop else None, mount=mount,
        cloud_topic=args.cloud_topic, pose_topic=args.pose_topic,
        poses=poses, deskew=not args.no_deskew,
        max_rate=args.max_rate, max_offset=args.max_offset, odometry=odometry,
        pose_file=pose_file,
        origin=parse_origin(args.origin) if getattr(args, "origin", None) else (0.0, 0.0, 0.0))
