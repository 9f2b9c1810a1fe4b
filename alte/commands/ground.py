"""``alte ground INPUT --out OUTPUT``: classify a terrain tile's ground.

The tile (LAS/LAZ/PCD/PLY/npz/xyz, in metres) goes through one ground filter
(:mod:`alte.ground.filters`; ``--method``, ``--set KEY=VALUE``) and is written as
LAS/LAZ with ASPRS classes 2 (ground) and 1 (the rest), the classification's provenance
in its header (:func:`alte.io.points.tiles.write_classified`). The summary gives the ground
share and the time of each step.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

from alte.commands.options import add_ground_options, ground_spec
from alte.errors import ParameterError
from alte.fsutil import refuse_overwrite
from alte.ground.filters import filter_ground
from alte.ground.settings import DEFAULT_METHOD
from alte.io.points.tiles import read_tile, tile_crs, write_classified

__all__ = ["add_parser", "run"]


def add_parser(subparsers: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register ``alte ground``."""
    p = subparsers.add_parser(
        "ground", help="classify a terrain tile's ground points (ASPRS class 2) into LAS/LAZ",
        description="Classify every point of INPUT (LAS/LAZ, PCD, PLY, npz or xyz, "
                    "coordinates in metres) as ground or not with one ground filter and "
                    "write OUTPUT (.las/.laz) with classes 2 (ground) and 1 (the rest); a "
                    "LAS/LAZ input keeps its other dimensions and header records. The "
                    "method, its settings and their source go into OUTPUT's header.")
    p.add_argument("input", type=Path, help="terrain tile: LAS/LAZ, PCD, PLY, npz or xyz")
    p.add_argument("--out", type=Path, required=True, metavar="OUTPUT",
                   help="the classified tile to write (.las or .laz)")
    add_ground_options(p)
    p.add_argument("--crs", default=None, metavar="CRS",
                   help="coordinate reference system of a tile whose header names none "
                        "(e.g. EPSG:32632; projected, in metres); written into OUTPUT")
    p.add_argument("--force", action="store_true", help="overwrite OUTPUT if it exists")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Read, filter, write, print the summary."""
    named, settings = ground_spec(args)
    method = named or DEFAULT_METHOD
    if args.out.suffix.lower() not in (".las", ".laz"):
        raise ParameterError(f"--out {args.out}: the output is LAS or LAZ (.las, .laz)")
    refuse_overwrite(args.out, args.force)
    start = time.perf_counter()
    tile = read_tile(args.input)
    crs = tile_crs(tile, args.crs)
    read_s = time.perf_counter() - start
    start = time.perf_counter()
    result = filter_ground(tile.points, method, settings)
    filter_s = time.perf_counter() - start
    provenance: dict[str, object] = {**result.provenance(), "input": str(args.input)}
    start = time.perf_counter()
    write_classified(args.out, tile, result.ground, provenance, crs=crs,
                     overwrite=args.force)
    write_s = time.perf_counter() - start
    summary = {**provenance, "output": str(args.out), "ground_share": round(result.share, 4),
               "crs": crs.name if crs is not None else None, "read_s": round(read_s, 3),
               "filter_s": round(filter_s, 3), "filter_cpu_s": round(result.cpu_s, 3),
               "write_s": round(write_s, 3),
               "points_per_s": round(len(tile.points) / max(filter_s, 1e-9))}
    if args.json:
        print(json.dumps(summary, sort_keys=True))
    else:
        for key, value in summary.items():
            print(f"{key}: {value}")
    return 0
