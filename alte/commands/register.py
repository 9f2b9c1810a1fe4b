"""``alte register``: an input's LiDAR frames -> one inertial point cloud file (thesis 2.1.3).

A point file is one frame: its summary speaks of the file's rows rather than of scans,
and its other fields (intensity, colours, labels, ...) go into ``--out`` where that format
can hold them (every point kept, no ``--voxel``)."""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from alte.commands.options import add_frame_options, frame_spec
from alte.errors import ParameterError, PointFileError
from alte.export import export_registered
from alte.fsutil import refuse_overwrite
from alte.io.points.pointfiles import WRITE_SUFFIXES, storable, write_points
from alte.io.points.pointformats import Fields
from alte.pipeline import InputKind, StreamCounts, merge_frames, open_input, prepare
from alte.registration import RegistrationCounts

__all__ = ["add_parser", "format_counts", "format_file_counts", "pose_line", "run"]


def add_parser(subparsers: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register ``alte register``."""
    p = subparsers.add_parser(
        "register", help="register a bag's scans into one inertial point cloud",
        description="Transform every scan of INPUT into the inertial frame with the pose at its "
                    "stamp (thesis eq. 2.2), drop fast-manoeuvre frames, crop to the control "
                    "volume, grid-average down-sample, merge, and write the cloud. Values that "
                    "start with '-' need '=': --crop=-5,-5,-1,5,5,3.")
    add_frame_options(p)
    p.add_argument("--out", type=Path, required=True,
                   help="output cloud: .ply, .pcd, .npz, .las, .laz, .xyz")
    p.add_argument("--mcap", type=Path, default=None, metavar="FILE",
                   help="also write the scans, poses, trajectory and cloud as a ROS 2 MCAP "
                        "(Foxglove, RViz)")
    p.add_argument("--force", action="store_true", help="overwrite --out / --mcap if they exist")
    p.set_defaults(func=run)


def format_counts(counts: RegistrationCounts) -> list[str]:
    """Human summary of what went in, was dropped and why, and came out."""
    c = counts
    return [
        f"frames: {c.frames_in} in, {c.frames_kept} kept; dropped "
        f"{c.frames_dropped_rate} (angular rate), {c.frames_dropped_offset} (pose offset), "
        f"{c.frames_dropped_empty} (no points left)",
        f"points: {c.points_in} in; dropped {c.points_dropped_nonfinite} (NaN/inf), "
        f"{c.points_dropped_crop} (outside crop box); {c.points_registered} after "
        f"per-frame down-sampling, {c.points_out} out",
    ]


def pose_line(counts: StreamCounts) -> str:
    """Where the poses came from, with the backend, its settings and refinement's counts."""
    poses = counts.poses
    if poses.method == "refine":
        kept = ", ".join(f"{n} {r}" for r, n in sorted(poses.kept.items()))
        return (f"refine ({poses.corrected} corrected, {poses.frames - poses.corrected} kept"
                + (f": {kept})" if kept else ")"))
    if poses.method:
        from alte.registration.odometry import OdometrySettings, odometry_label

        label = odometry_label(OdometrySettings.parse(poses.settings))
        rest = f", IMU biases from {poses.rest_s:.1f} s at rest" if poses.rest_s > 0 else ""
        swept = f", {poses.deskewed} scans deskewed" if poses.deskewed else ""
        return f"{poses.source} ({label}, {1e3 * poses.seconds / max(poses.frames, 1):.0f} " \
               f"ms per scan{rest}{swept})"
    return poses.source


def _reader_line(counts: StreamCounts) -> str:
    parts = ", ".join(f"{k.replace('_', ' ')} {v}" for k, v in counts.read.as_dict().items())
    return f"bag: {parts}" if parts else "bag: read"


def _check_mcap(path: Path, force: bool) -> None:
    if path.suffix.lower() != ".mcap":
        raise ParameterError(f"--mcap {path}: the file name must end in .mcap")
    refuse_overwrite(path, force)


def format_file_counts(path: Path, counts: StreamCounts) -> list[str]:
    """Human summary for a point file: its rows, what was dropped, what came out."""
    c, read = counts.registration, counts.read
    rows = c.points_in + read.points_nonfinite
    out = f"{c.points_registered} after down-sampling, " if c.points_registered != \
        c.points_in - c.points_dropped_crop else ""
    return [f"file: {path}: {rows} rows; dropped {read.points_nonfinite} (NaN/inf), "
            f"{c.points_dropped_crop} (outside crop box); {out}{c.points_out} points out"]


def _fields_line(out: Path, fields: Fields) -> tuple[Fields, str]:
    """The fields ``out`` can hold, and a line naming what is kept and what is not (why)."""
    kept, dropped = storable(out.suffix.lower(), fields)
    parts = [f"kept {', '.join(kept)}"] if kept else []
    parts += [f"not kept {name} ({why})" for name, why in dropped.items()]
    return kept, f"fields: {'; '.join(parts)}"


def run(args: argparse.Namespace) -> int:
    """Read, register, write; print the counts."""
    if args.out.suffix.lower() not in WRITE_SUFFIXES:
        raise PointFileError(f"--out {args.out}: unknown point file type; use {WRITE_SUFFIXES}")
    refuse_overwrite(args.out, args.force)  # fail before the long read
    spec, source = frame_spec(args), open_input(args.input)
    fields: Fields = {}
    if args.mcap is not None:
        _check_mcap(args.mcap, args.force)
        reg = prepare(source, spec, progress=True)
        cloud, counts = np.asarray(reg.cloud), reg.counts
        topics = export_registered(reg, args.mcap, overwrite=args.force)
        if source.kind is InputKind.POINTS:  # one frame: read again for its fields
            fields = merge_frames(source, spec).fields
    else:
        merged = merge_frames(source, spec, progress=True)
        cloud, counts, fields = merged.points, merged.counts, merged.fields
    kept, line = _fields_line(args.out, fields)
    write_points(args.out, cloud, overwrite=args.force, fields=kept)
    if source.kind is InputKind.POINTS:
        lines = format_file_counts(source.path, counts) + ([line] if fields else [])
    else:
        lines = [_reader_line(counts), *format_counts(counts.registration),
                 f"poses: {pose_line(counts)}"]
    print("\n".join([*lines, *(f"note: {n}" for n in counts.notes)]))
    print(f"wrote {len(cloud)} points to {args.out}")
    if args.mcap is not None:
        print(f"wrote {sum(topics.values())} messages to {args.mcap}: "
              + ", ".join(f"{t} {n}" for t, n in topics.items()))
    return 0
