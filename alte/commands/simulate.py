"""``alte simulate``: write the benchmark terrains (bag + ground truth + scenario.json)."""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

from tqdm.auto import tqdm

from alte.errors import ParameterError
from alte.sim.profile import PROFILES, SensorProfile, get_profile
from alte.sim.scenario import SCENARIO_FILE, update_terrain
from alte.sim.terrains import TERRAINS

__all__ = ["add_parser", "run"]


def add_parser(subparsers: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register ``alte simulate``."""
    p = subparsers.add_parser(
        "simulate", help="simulate benchmark terrains as ROS 2 bags with ground truth",
        description="Fly the simulated VLP-16 over a thesis terrain (or all eight) and write "
                    "DIR/NAME/: a ROS 2 bag, ground_truth.ply (object id per triangle) and "
                    "scenario.json. A folder whose spec and seed match is reused. "
                    f"Terrains: {', '.join(TERRAINS)}.")
    p.add_argument("name", metavar="NAME|all", help="terrain name, or 'all'")
    p.add_argument("--out", type=Path, default=Path("data"), metavar="DIR",
                   help="output folder (default: data)")
    p.add_argument("--seed", type=int, default=0, help="noise seed (default: 0)")
    p.add_argument("--frames", type=int, default=None, metavar="N",
                   help="simulate N evenly spaced scans of the mission (quick runs; "
                        "written to DIR/NAME-Nf so the full mission is kept)")
    p.add_argument("--storage", choices=("sqlite3", "mcap"), default="sqlite3",
                   help="rosbag2 storage plugin (default: sqlite3)")
    p.add_argument("--force", action="store_true", help="simulate even if the folder is current")
    p.add_argument("--profile", choices=list(PROFILES), default="thesis",
                   help="sensor profile: thesis (instantaneous scans, no IMU: the chapters' "
                        "reproduction) or uav (each firing cast at its instant, per-point "
                        "time, 200 Hz IMU, 50 Hz poses, dropouts); written to "
                        "DIR/NAME-PROFILE (default: thesis)")
    p.add_argument("--sensor-set", action="append", default=[], metavar="KEY=VALUE",
                   dest="sensor_sets",
                   help="change one setting of the profile (repeatable): "
                        + "; ".join(f"{k}: {v}" for k, v in SensorProfile.help().items())
                        .replace("%", "%%"))
    p.set_defaults(func=run)


def _profile(args: argparse.Namespace) -> SensorProfile:
    """The profile of ``--profile`` with ``--sensor-set`` applied (errors name the flags)."""
    changes: dict[str, str] = {}
    for item in args.sensor_sets:
        key, sep, value = item.partition("=")
        if not sep or not key.strip():
            raise ParameterError(f"--sensor-set {item!r}: expected KEY=VALUE")
        changes[key.strip()] = value.strip()
    try:
        return get_profile(args.profile, changes)
    except ParameterError as err:
        raise ParameterError(f"--sensor-set: {err}") from err


def run(args: argparse.Namespace) -> int:
    """Simulate the requested terrains; one summary line each."""
    names = list(TERRAINS) if args.name == "all" else [args.name]
    profile = _profile(args)
    for name in tqdm(names, desc="terrains", unit="terrain", disable=len(names) == 1):
        start = time.perf_counter()
        folder, made = update_terrain(name, args.out, args.seed, args.frames,
                                      storage=args.storage, force=args.force, progress=True,
                                      profile=profile)
        counts = json.loads((folder / SCENARIO_FILE).read_text())["counts"]
        state = f"simulated in {time.perf_counter() - start:.1f} s" if made else "up to date"
        tqdm.write(f"{name}: {counts['frames']} frames, {counts['returns']} points, "
                   f"{counts['poses']} poses -> {folder} ({state})")
    return 0
