"""``alte info INPUT``: a bag's topics, counts, duration and the cloud/pose topics alte would use.

``alte info --mappers`` lists the mappers instead: the thesis' four and every plugin the
registry finds (:mod:`alte.mappers.registry`), each loaded and checked, with where it came
from and, for a plugin it refuses, why.

For a terrain folder (``alte simulate``) it also shows what the pipeline takes from it:
the control volume (crop and domain) and the registration voxel. For a point file it
describes the file: format, encoding, fields, points, NaN rows, bounds.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import TYPE_CHECKING

from alte.errors import ParameterError
from alte.io.bags.baginfo import BagInfo, inspect_bag
from alte.pipeline.source import InputKind, Source, open_input

if TYPE_CHECKING:
    from alte.io.points.pointfiles import PointSummary

__all__ = ["add_parser", "format_info", "format_mappers", "format_points", "imu_topics",
           "odometry_choice", "pose_source", "run"]


def add_parser(subparsers: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register ``alte info``."""
    p = subparsers.add_parser(
        "info",
        help="show a bag's topics (or a point file's contents) and what alte detects",
        description="List the topics of INPUT (ROS 1 .bag file, ROS 2 bag folder, or a terrain "
        "folder) with their types and message counts, the duration, the detected cloud and "
        "pose topics and the /tf_static sensor mount; or describe a point file (.pcd, .ply, "
        ".las, .laz, .npz, .xyz): format, encoding, fields, points, NaN rows, bounds.",
    )
    p.add_argument("input", type=Path, nargs="?", default=None,
                   help="ROS 1 .bag file, ROS 2 bag folder, a terrain folder, or a point file")
    p.add_argument("--mappers", action="store_true",
                   help="list the mappers (built-in and plugins, each checked against the "
                        "mapper contract) instead of describing INPUT")
    p.add_argument("--json", action="store_true", help="print one JSON object instead of text")
    p.add_argument("--cloud-topic", default=None, help="PointCloud2 / VelodyneScan topic")
    p.add_argument("--pose-topic", default=None, help="pose / odometry / TF topic")
    p.set_defaults(func=run)


def imu_topics(info: BagInfo) -> list[str]:
    """The bag's ``sensor_msgs/msg/Imu`` topics."""
    from alte.io.bags.imu import IMU_TYPE

    return [name for name, (kind, _) in info.topics.items() if kind == IMU_TYPE]


def odometry_choice(info: BagInfo) -> str:
    """Which odometry ``--poses odometry`` runs by default (``--odometry auto``)."""
    from alte.registration.odometry import OdometrySettings, odometry_label, resolve_method

    imus = imu_topics(info)
    label = odometry_label(resolve_method(OdometrySettings(), bool(imus)))
    if imus:
        return f"LiDAR-inertial odometry ({label}, IMU {imus[0]})"
    return f"LiDAR odometry ({label})"


def pose_source(info: BagInfo) -> str:
    """What ``alte map``/``register`` use for poses by default (``--poses`` unset)."""
    if info.pose_topic:
        return f"recorded ({info.pose_topic}); --poses odometry: {odometry_choice(info)}"
    return (f"odometry (no pose topic: {odometry_choice(info)} unless --odometry says "
            "otherwise, in the first scan's body frame)")


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
    lines.append(f"poses:     {pose_source(info)}")
    if info.mount is not None:
        lines.append(f"mount:     {info.mount.to_string()} (x,y,z m, roll,pitch,yaw deg)")
    lines += [f"note:      {note}" for note in info.notes]
    return lines


def _terrain(source: Source) -> dict[str, object]:
    if source.kind is not InputKind.TERRAIN:
        return {}
    crop = None if source.control is None else list(source.control.values())
    return {"terrain": source.name, "title": source.title, "control_volume": crop,
            "voxel": source.voxel}


def format_terrain(terrain: dict[str, object]) -> list[str]:
    """Lines for a terrain folder's settings."""
    if not terrain:
        return []
    return [f"terrain:   {terrain['terrain']} ({terrain['title']})",
            f"control:   {terrain['control_volume']} (xmin,ymin,zmin,xmax,ymax,zmax m: crop "
            "and map domain)",
            f"voxel:     {terrain['voxel']} m (registration grid)"]


def format_points(about: PointSummary) -> list[str]:
    """Human-readable lines describing a point file (:func:`describe_points`)."""
    fields = ", ".join(f"{f['name']} {f['type']}" + (f" x{f['count']}" if f["count"] > 1 else "")
                       for f in about["fields"])
    lines = [f"file:      {about['file']}", f"format:    {about['format']}, {about['encoding']}",
             f"fields:    {fields}",
             f"points:    {about['rows']} rows: {about['points']} finite, "
             f"{about['nonfinite']} non-finite ({about['nan']} with NaN)"]
    if about.get("height", 1) > 1:
        lines.append(f"layout:    organised, {about['width']} x {about['height']}")
    if about["bounds"] is not None:
        lo, hi = about["bounds"]
        lines.append("bounds:    " + ", ".join(f"{c} {a:.3f} .. {b:.3f}"
                                               for c, a, b in zip("xyz", lo, hi, strict=True)))
    ranges = about["field_ranges"]
    lines += ["ranges:"] * bool(ranges)
    lines += [f"  {name:<12} {lo:.6g} .. {hi:.6g}" for name, (lo, hi) in ranges.items()]
    return lines


def format_mappers(rows: list[dict[str, str]]) -> list[str]:
    """One line per mapper (:func:`alte.mappers.registry.describe`), refusals after it."""
    width = max(len(r["name"]) for r in rows)
    lines = []
    for r in rows:
        if r["status"] == "ok":
            lines.append(f"{r['name']:<{width}}  {r['dims']}  {r['title']}  ({r['origin']}: "
                         f"{r['target']})")
        else:
            lines.append(f"{r['name']:<{width}}  REFUSED  {r['status']}")
    return lines


def _mappers(as_json: bool) -> int:
    from alte.mappers import registry

    rows = [registry.describe(e) for e in registry.entries()]
    rows += [{"name": key, "title": "", "dims": "", "origin": "", "target": "",
              "status": why} for key, why in registry.refused().items()]
    print(json.dumps(rows) if as_json else "\n".join(format_mappers(rows)))
    return 0 if all(r["status"] == "ok" for r in rows) else 1


def run(args: argparse.Namespace) -> int:
    """Inspect the input (or list the mappers) and print the summary."""
    if args.mappers:
        return _mappers(args.json)
    if args.input is None:
        raise ParameterError("give INPUT (a bag, terrain folder or point file) "
                             "or --mappers")
    source = open_input(args.input)
    if source.kind is InputKind.POINTS:
        from alte.io.points.pointfiles import describe_points  # pandas, numba: point files only

        about = describe_points(source.path)
        print(json.dumps(about, sort_keys=True) if args.json else "\n".join(format_points(about)))
        return 0
    assert source.bag is not None  # bags and terrain folders have one
    info = inspect_bag(source.bag, cloud_topic=args.cloud_topic, pose_topic=args.pose_topic)
    terrain = _terrain(source)
    if args.json:
        print(json.dumps({**info.to_dict(), **terrain, "pose_source": pose_source(info)},
                         sort_keys=True))
    else:
        print("\n".join(format_info(info) + format_terrain(terrain)))
    return 0
