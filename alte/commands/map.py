"""``alte map``: a bag (frame by frame) or a point file (batch) -> a terrain map and its metrics.

A bag is read and registered frame by frame, each frame inserted into the mapper
as it would be in flight; a point file is built in one call. ``elapsed_s`` times
only the mapper's ``insert``/``build`` calls (thesis 5.2.1: mapping only, without
reading, registration or down-sampling).
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path
from typing import Any

import numpy as np

from alte.errors import MapperError, ParameterError
from alte.fsutil import atomic_path, refuse_overwrite

__all__ = ["add_parser", "check_export", "export_cells", "parse_origin", "parse_sets", "run",
           "run_map"]

EXPORT_SUFFIXES = (".npz", ".bt")


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register ``alte map``."""
    p = subparsers.add_parser(
        "map", help="build a terrain map from a bag or a point cloud file",
        description="Build a map with one of the mappers (quadtree, octomap, alte2d, alte3d). "
                    "A bag is registered and inserted frame by frame; a point file is built in "
                    "one batch. Values that start with '-' need '=': --origin=-1,0,2.")
    p.add_argument("input", type=Path, help="ROS bag (file or folder) or point file")
    p.add_argument("--mapper", required=True, help="quadtree, octomap, alte2d or alte3d")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", dest="sets",
                   help="mapper parameter (repeatable), e.g. --set kappa=0.1")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--export", type=Path, default=None, metavar="FILE",
                   help="write the cells (.npz) or an OctoMap tree (.bt, octomap only)")
    p.add_argument("--force", action="store_true", help="overwrite --export if it exists")
    p.add_argument("--voxel", type=float, default=None, metavar="M",
                   help="grid-average down-sampling cell (m), per frame for bags")
    p.add_argument("--origin", default="0,0,0", metavar="X,Y,Z",
                   help="sensor origin for a point file (default 0,0,0)")
    p.add_argument("--mount", default=None, metavar="X,Y,Z,ROLL,PITCH,YAW",
                   help="sensor mount for a bag (default: the bag's)")
    p.set_defaults(func=run)


def parse_sets(items: list[str]) -> dict[str, str]:
    """``["k=v", ...]`` -> ``{"k": "v"}``; an item without '=' raises."""
    out: dict[str, str] = {}
    for item in items:
        key, sep, value = item.partition("=")
        if not sep or not key.strip():
            raise ParameterError(f"--set {item!r}: expected KEY=VALUE")
        out[key.strip()] = value.strip()
    return out


def parse_origin(text: str) -> np.ndarray:
    """``"x,y,z"`` -> (3,) array."""
    try:
        values = np.array([float(v) for v in text.split(",")])
    except ValueError as err:
        raise ParameterError(f"--origin {text!r}: expected 3 numbers x,y,z") from err
    if values.shape != (3,) or not np.isfinite(values).all():
        raise ParameterError(f"--origin {text!r}: expected 3 finite numbers x,y,z")
    return values


def _is_point_file(path: Path) -> bool:
    from alte.io.pointfiles import READ_SUFFIXES

    return not path.is_dir() and path.name.lower().endswith(READ_SUFFIXES)


def _local_origin(mapper: Any, anchor: np.ndarray) -> np.ndarray:
    """Shift for mappers with a fixed key space around 0 (no ``domain``: Octomap).

    UTM-scale clouds (1e6-1e7 m) fall outside such a key space and lose centimetres
    in float32; they are mapped relative to ``anchor`` (a sensor origin or the median
    point, so a far outlier cannot move it) rounded to 1 km, added back on export.
    Domain-anchored mappers are exact at any offset and keep their coordinates.
    """
    from alte.io.pointfiles import local_origin

    if "domain" in mapper.params:
        return np.zeros(3)
    return local_origin(np.reshape(anchor, (1, 3)))


def _map_points(mapper: Any, path: Path, voxel: float | None, origin: np.ndarray) -> dict:
    from alte.io.pointfiles import read_points_info
    from alte.registration import grid_average

    info = read_points_info(path)
    points = info.points
    if voxel is not None:
        points = grid_average(points, voxel)
    shift = _local_origin(mapper, np.median(points, axis=0))
    start = time.perf_counter()
    mapper.build(points - shift, origin - shift)
    return {"frames": 1, "points": len(points), "elapsed_s": time.perf_counter() - start,
            "local_origin": shift.tolist(), "points_dropped_nonfinite": info.nonfinite}


def _with_domain(mapper: Any, clouds: list[np.ndarray]) -> Any:
    """``mapper`` with its unset ``domain`` fixed to the bounding cube of all ``clouds``.

    Frame-by-frame insertion needs the root cell fixed before the first frame (3D-ALTE
    refuses without one; the 2D mappers would grow a power-of-two root instead). All
    registered frames are known here, so the cube over them is the thesis' "overall
    domain"; a ``--set domain=...`` of the user's is kept.
    """
    if mapper.params.get("domain", None) != "" or not clouds:
        return mapper
    points = np.concatenate(clouds)
    lo, hi = points.min(axis=0), points.max(axis=0)
    edge = float(np.max(hi - lo)) * (1 + 1e-9) + 1e-6  # lo + edge must not round below hi
    domain = ",".join(repr(float(v)) for v in (*lo, edge))
    return type(mapper)(**{**mapper.params, "domain": domain})


def _map_bag(mapper: Any, path: Path, voxel: float | None,
             mount_text: str | None) -> tuple[Any, dict]:
    from alte.io.bag import read_frames
    from alte.registration import register_frames
    from alte.types import Mount

    mount = Mount.from_string(mount_text) if mount_text else None
    frameset = read_frames(path, mount=mount, progress=True)
    kept = [(pts, origin) for _f, pts, origin in register_frames(
        frameset.frames, frameset.mount, voxel=voxel, progress=True)]
    mapper = _with_domain(mapper, [pts for pts, _ in kept])
    shift = _local_origin(mapper, kept[0][1]) if kept else np.zeros(3)
    elapsed = 0.0
    for pts, origin in kept:
        start = time.perf_counter()
        mapper.insert(pts - shift, origin - shift)
        elapsed += time.perf_counter() - start
    return mapper, {"frames": len(kept), "points": sum(len(p) for p, _ in kept),
                    "elapsed_s": elapsed, "local_origin": shift.tolist(),
                    "points_dropped_nonfinite": int(frameset.counts["points_nonfinite"])}


def check_export(path: Path, mapper: Any, overwrite: bool) -> None:
    """Fail before mapping when ``path`` cannot be written (type, .bt support, exists)."""
    suffix = path.suffix.lower()
    if suffix not in EXPORT_SUFFIXES:
        raise MapperError(f"--export {path}: unknown type; use {', '.join(EXPORT_SUFFIXES)}")
    if suffix == ".bt" and not hasattr(mapper, "write_bt"):
        raise MapperError(f"--export {path}: mapper {mapper.name!r} cannot write .bt "
                          "(only octomap can); export .npz instead")
    refuse_overwrite(path, overwrite)


def export_cells(mapper: Any, path: Path, overwrite: bool = False,
                 shift: np.ndarray | None = None) -> None:
    """Write ``mapper``'s cells to ``path`` (.npz) or its OctoMap tree (.bt), atomically.

    ``shift`` (the local origin the points were mapped relative to) is added back to
    the exported cell centres. A ``.bt`` goes through the mapper's own
    ``write_bt(path, overwrite=...)`` and stays in the mapper's (local) coordinates.
    """
    check_export(path, mapper, overwrite)
    if path.suffix.lower() == ".bt":
        mapper.write_bt(path, overwrite=overwrite)
        return
    arrays = mapper.cells().as_dict()
    if shift is not None:
        arrays["centers"] = arrays["centers"] + np.asarray(shift, dtype=np.float64)
    with atomic_path(path, overwrite=overwrite) as tmp, tmp.open("wb") as fh:
        np.savez(fh, **arrays)


def run_map(mapper: Any, path: Path, voxel: float | None = None,
            origin: np.ndarray | None = None,
            mount: str | None = None) -> tuple[Any, dict[str, Any]]:
    """Feed ``path`` (bag or point file) to ``mapper``; return the mapper used and a summary.

    For a bag the mapper may be a copy with its ``domain`` fixed (see :func:`_with_domain`).
    """
    if voxel is not None and not (np.isfinite(voxel) and voxel > 0):
        raise ParameterError(f"--voxel {voxel!r}: must be > 0")
    if _is_point_file(path):
        origin = np.zeros(3) if origin is None else origin
        counts = _map_points(mapper, path, voxel, origin)
    else:
        mapper, counts = _map_bag(mapper, path, voxel, mount)
    cells = mapper.cells()
    return mapper, {
        "mapper": mapper.name, "params": mapper.params, "input": str(path), **counts,
        "basis_functions": int(mapper.basis_functions), "cells": len(cells),
        "occupied_cells": int(np.count_nonzero(cells.occupied)),
        "memory_bytes": int(mapper.memory_bytes),
        "points_outside": int(getattr(mapper, "points_outside", 0)),
    }


def run(args: argparse.Namespace) -> int:
    """Build the map, print the summary, export when asked."""
    from alte.mappers import make_mapper

    params = parse_sets(args.sets)
    origin = parse_origin(args.origin)
    mapper = make_mapper(args.mapper, **params)
    if args.export is not None:
        check_export(args.export, mapper, args.force)  # fail before the long work
    mapper, summary = run_map(mapper, args.input, args.voxel, origin, args.mount)
    if args.export is not None:
        export_cells(mapper, args.export, args.force, np.asarray(summary["local_origin"]))
        summary["export"] = str(args.export)
    if args.json:
        print(json.dumps(summary, sort_keys=True))
    else:
        for key in ("mapper", "params", "input", "frames", "points", "points_dropped_nonfinite",
                    "points_outside", "local_origin", "elapsed_s", "basis_functions",
                    "occupied_cells", "memory_bytes", "export"):
            if key in summary:
                print(f"{key}: {summary[key]}")
    return 0
