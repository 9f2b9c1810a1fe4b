"""``alte odometry``: LiDAR odometry and pose refinement scored on the simulated terrains.

Writes ``odometry.csv`` (ATE and mean distance to the true mesh with recorded,
odometry and refined poses, per terrain; :mod:`alte.studies.odometry`) into
``--out`` (default ``reports/tables``) and prints it.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import pandas as pd

from alte.fsutil import refuse_overwrite
from alte.paths import resolve
from alte.studies.odometry import odometry_table, write_odometry_table

__all__ = ["add_parser", "run"]


def add_parser(subparsers: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register ``alte odometry``."""
    p = subparsers.add_parser(
        "odometry", help="score LiDAR odometry and pose refinement on the simulated terrains",
        description="Register each terrain's mission with recorded, odometry and refined "
                    "poses; table the trajectory error (ATE after rigid alignment) and the "
                    "cloud's mean distance to the true mesh. Terrains are simulated first "
                    "when absent.")
    p.add_argument("terrains", nargs="*", help="terrain names (default: all eight)")
    p.add_argument("--data", type=Path, default=Path("data"), metavar="DIR",
                   help="terrain folders and the registration cache (default data/)")
    p.add_argument("--frames", type=int, default=None, metavar="N",
                   help="a reduced mission of N evenly spaced scans (default: every scan, "
                        "10 Hz, as odometry needs)")
    p.add_argument("--seed", type=int, default=0, help="simulation seed (default 0)")
    p.add_argument("--out", type=Path, default=Path("reports/tables"), metavar="DIR",
                   help="where odometry.csv goes (default reports/tables)")
    p.add_argument("--force", action="store_true", help="overwrite odometry.csv")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Build, write and print the table."""
    out = resolve(args.out)
    refuse_overwrite(out / "odometry.csv", args.force)  # fail before the long registrations
    table = odometry_table(args.terrains or None, resolve(args.data), args.frames, args.seed)
    path = write_odometry_table(table, out, overwrite=args.force)
    with pd.option_context("display.width", 200, "display.max_columns", 30):
        print(table.to_string(index=False, float_format=lambda v: f"{v:.4g}"))
    print(f"wrote {path}")
    return 0
