"""``alte odometry``: score every pose source of a recording against reference poses.

Inputs are simulated terrain names (the simulator's true poses are the reference) or bags
and terrain folders (the bag's pose topic, or ``--reference FILE.tum``). Writes
``odometry.csv`` (ATE, RPE, cloud distance to the reference-pose cloud, ms per scan, per
input and pose source; :mod:`alte.lab.studies.poses.benchmark`) into ``--out`` (default
``reports/tables``) and prints it.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import pandas as pd

from alte.commands.options import parse_key_values
from alte.errors import ParameterError
from alte.fsutil import refuse_overwrite
from alte.lab.studies.poses.benchmark import SOURCES, odometry_table, write_odometry_table
from alte.paths import resolve
from alte.registration.odometry import KEYS, METHODS, odometry_params

__all__ = ["add_parser", "run"]


def add_parser(subparsers: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register ``alte odometry``."""
    p = subparsers.add_parser(
        "odometry", help="score recorded, odometry and refined poses against reference poses",
        description="Register each input with every pose source (recorded, each odometry "
                    "backend, refine); table ATE and RPE (evo, after rigid alignment), the "
                    "registered cloud's median / p90 distance to the cloud registered with "
                    "the reference poses, and the milliseconds per scan of the pose step. "
                    "Terrains are simulated first when absent.")
    p.add_argument("inputs", nargs="*", metavar="INPUT",
                   help="terrain names or bag / terrain folders (default: the eight terrains)")
    p.add_argument("--reference", type=Path, default=None, metavar="FILE",
                   help="reference poses of a bag as a TUM file (default: its pose topic)")
    p.add_argument("--sources", default=",".join(SOURCES), metavar="A,B",
                   help=f"pose sources to score (default {','.join(SOURCES)})")
    p.add_argument("--odometry-set", action="append", default=[], metavar="SOURCE:KEY=VALUE",
                   dest="odometry_sets",
                   help="a setting of one source, e.g. kiss:voxel=0.5 or refine:min_gain=0.3 "
                        "(repeatable)")
    p.add_argument("--voxel", type=float, default=None, metavar="M",
                   help="clouds' grid (default: a terrain's own, else 0.05 m)")
    p.add_argument("--data", type=Path, default=Path("data"), metavar="DIR",
                   help="terrain folders and the registration cache (default data/)")
    p.add_argument("--frames", type=int, default=None, metavar="N",
                   help="N evenly spaced scans (default: every scan, as odometry needs)")
    p.add_argument("--seed", type=int, default=0, help="simulation seed (default 0)")
    p.add_argument("--out", type=Path, default=Path("reports/tables"), metavar="DIR",
                   help="where odometry.csv goes (default reports/tables)")
    p.add_argument("--name", default="odometry", help="table name (default odometry)")
    p.add_argument("--force", action="store_true", help="overwrite the table")
    p.set_defaults(func=run)


def _settings(items: list[str]) -> dict[str, dict[str, str]]:
    """``SOURCE:KEY=VALUE`` items by source, each checked against that source's settings."""
    out: dict[str, dict[str, str]] = {}
    for item in items:
        source, sep, rest = item.partition(":")
        if not sep or source not in (*METHODS, "refine"):
            raise ParameterError(f"--odometry-set {item!r}: expected SOURCE:KEY=VALUE with "
                                 f"SOURCE one of {', '.join((*METHODS, 'refine'))}")
        out.setdefault(source, {}).update(parse_key_values([rest], "--odometry-set"))
    for source, given in out.items():
        unknown = sorted(set(given) - set(KEYS[source]))
        if unknown:
            raise ParameterError(f"--odometry-set {source}:{unknown[0]}: not a setting of "
                                 f"{source}; valid: {', '.join(KEYS[source])}")
        try:
            odometry_params(source if source in METHODS else None, given)
        except ParameterError as err:
            raise ParameterError(f"--odometry-set {source}: {err}") from err
    return out


def _check(args: argparse.Namespace) -> list[str]:
    sources = [s.strip() for s in args.sources.split(",") if s.strip()]
    unknown = sorted(set(sources) - set(SOURCES))
    if unknown or not sources:
        raise ParameterError(f"--sources {args.sources!r}: valid sources are "
                             f"{', '.join(SOURCES)}")
    if args.frames is not None and args.frames < 3:
        raise ParameterError(f"--frames {args.frames}: need at least 3 scans")
    if args.voxel is not None and not args.voxel > 0:
        raise ParameterError(f"--voxel {args.voxel}: must be > 0")
    if args.reference is not None and not args.reference.is_file():
        raise ParameterError(f"--reference {args.reference}: no such TUM file")
    return sources


def run(args: argparse.Namespace) -> int:
    """Build, write and print the table."""
    sources, settings = _check(args), _settings(args.odometry_sets)
    out = resolve(args.out)
    refuse_overwrite(out / f"{args.name}.csv", args.force)  # fail before the registrations
    table = odometry_table(args.inputs or None, reference=args.reference,
                           data_dir=resolve(args.data), frames=args.frames, seed=args.seed,
                           voxel=args.voxel, sources=sources, settings=settings)
    path = write_odometry_table(table, out, overwrite=args.force, name=args.name)
    with pd.option_context("display.width", 250, "display.max_columns", 30,
                           "display.max_colwidth", 40):
        print(table.to_string(index=False, float_format=lambda v: f"{v:.4g}"))
    print(f"wrote {path}")
    return 0
