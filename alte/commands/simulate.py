"""``alte simulate``: write the benchmark terrains (bag + ground truth + scenario.json), or
import real terrain tiles (LAS/LAZ, with or without a ground class; an ISPRS-style pair; a
DEM) and fly the thesis' landing or navigation mission over them into the same kind of
folder. A tile's ground is its producer's class; a tile without one, or every tile when
``--ground-method`` is named, is classified with the ground stage's filter
(:mod:`alte.sim.real.ground`)."""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

from tqdm.auto import tqdm

from alte.commands.options import add_ground_options, ground_spec, parse_key_values
from alte.errors import ParameterError
from alte.sim.profile import PROFILES, SensorProfile, get_profile
from alte.sim.real import (
    GROUND_CLASS,
    MISSIONS,
    Flight,
    GroundChoice,
    import_terrain,
    write_imported,
)
from alte.sim.real.tiles import POINT_SUFFIXES, RASTER_SUFFIXES
from alte.sim.scenario import SCENARIO_FILE, update_terrain
from alte.sim.terrains import TERRAINS

__all__ = ["add_parser", "run"]


def add_parser(subparsers: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register ``alte simulate``."""
    p = subparsers.add_parser(
        "simulate", help="simulate the benchmark terrains, or import real terrain tiles and "
                         "fly them, as ROS 2 bags with ground truth",
        description="Fly the simulated VLP-16 over a thesis terrain (or all eight) and write "
                    "DIR/NAME/: a ROS 2 bag, ground_truth.ply (object id per triangle) and "
                    "scenario.json. A folder whose spec and seed match is reused. "
                    f"Terrains: {', '.join(TERRAINS)}. Given terrain tiles instead (LAS/LAZ, "
                    "a PCD with --ground, a DEM as GeoTIFF or ESRI ASCII grid; several "
                    "adjacent or overlapping tiles of one CRS make one terrain), import them "
                    "as a terrain (bare earth, object surface and objects from the classes, "
                    "CRS and units in scenario.json, bare_earth.npz) and fly --mission over "
                    "it into DIR/NAME/. A LAS/LAZ tile's ground is its ground class (2); one "
                    "without any is classified with the ground filter (--ground-method), "
                    "and how ground was told is recorded in scenario.json.")
    p.add_argument("name", nargs="+", metavar="NAME|all|TILE",
                   help="terrain name, 'all', or one or more terrain tiles to import")
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
    _add_import_options(p)
    p.set_defaults(func=run)


def _add_import_options(p: argparse.ArgumentParser) -> None:
    """The flags of a tile import (ignored for the built-in terrains)."""
    g = p.add_argument_group("importing real terrain tiles")
    g.add_argument("--mission", choices=list(MISSIONS), default="landing",
                   help="the thesis' mission flown over the tiles: landing (lawnmower, 10 m) "
                        "or navigation (edge loop and middle pass, 14 m), sized to the tiles "
                        "(default: landing)")
    g.add_argument("--name", default=None, dest="name_",
                   help="the terrain's name (default: the first tile's stem and _lan/_nav)")
    g.add_argument("--crs", default=None, metavar="CRS",
                   help="CRS of tiles whose file states none, e.g. EPSG:32632 (pyproj's "
                        "forms); its units (metres, feet) scale the coordinates to metres")
    g.add_argument("--ground", type=Path, default=None, metavar="FILE",
                   help="the tile's bare-earth points (an ISPRS-style pair: the tile holds "
                        "every point, FILE the reference ground among them)")
    g.add_argument("--ground-class", type=int, default=None, metavar="N",
                   help=f"class of the ground points in LAS/LAZ (default: {GROUND_CLASS}, "
                        "and the ground filter for a tile with no point of it; a class "
                        "named here that a tile lacks is an error)")
    add_ground_options(g, "ground-",
                       "classify every LAS/LAZ tile with this ground filter, replacing the "
                       "producer's ground class (without it a tile keeps its class, and one "
                       "with no point of it is classified with the default filter)")
    g.add_argument("--cell", type=float, default=None, metavar="M",
                   help="cell of the surfaces in metres (default: a DEM's own, else about two "
                        "first returns a cell, at least 1 m)")
    g.add_argument("--region", default=None, metavar="XMIN,YMIN,XMAX,YMAX",
                   help="import only this part of the tiles (in their CRS units)")
    for key in ("altitude", "speed", "spacing", "clearance"):
        g.add_argument(f"--{key}", type=float, default=None, metavar="M",
                       help=f"flight {key}: {Flight.help()[key]}".replace("%", "%%"))


def _profile(args: argparse.Namespace) -> SensorProfile:
    """The profile of ``--profile`` with ``--sensor-set`` applied (errors name the flags)."""
    changes = parse_key_values(args.sensor_sets, "--sensor-set")
    try:
        return get_profile(args.profile, changes)
    except ParameterError as err:
        raise ParameterError(f"--sensor-set: {err}") from err


def _ground_by(args: argparse.Namespace) -> GroundChoice:
    """``--ground-class``, ``--ground-method`` and ``--ground-set`` as one choice."""
    method, settings = ground_spec(args, "ground-")
    named = method is not None or bool(args.ground_sets)
    return GroundChoice(args.ground_class, method, settings if named else None)


def _is_tile(text: str) -> bool:
    return Path(text).suffix.lower() in (*POINT_SUFFIXES, *RASTER_SUFFIXES) or \
        Path(text).is_file()


def _flight(args: argparse.Namespace) -> Flight:
    given = {k: getattr(args, k) for k in ("altitude", "speed", "spacing", "clearance")
             if getattr(args, k) is not None}
    try:
        return Flight(mission=args.mission).replace(**given)
    except ParameterError as err:  # "flight: altitude=-1.0 out of range" -> "--altitude -1.0 ..."
        text = str(err).removeprefix(f"{Flight.OWNER}: ").replace("=", " ", 1)
        raise ParameterError(f"--{text}") from err


def _region(text: str | None) -> tuple[float, ...] | None:
    if text is None:
        return None
    try:
        values = tuple(float(v) for v in text.split(","))
    except ValueError as err:
        raise ParameterError(f"--region {text!r}: expected XMIN,YMIN,XMAX,YMAX") from err
    if len(values) != 4:
        raise ParameterError(f"--region {text!r}: expected 4 numbers XMIN,YMIN,XMAX,YMAX")
    return values


def _import(args: argparse.Namespace, profile: SensorProfile) -> int:
    """Import the tiles as a terrain and fly its mission; one summary line."""
    start = time.perf_counter()
    imported = import_terrain(args.name, _flight(args), name=args.name_, crs=args.crs,
                              ground=args.ground, ground_by=_ground_by(args),
                              cell=args.cell, region=_region(args.region))
    spec = imported.terrain.spec
    tqdm.write(f"{spec.name}: {imported.surfaces.shape[1]} x {imported.surfaces.shape[0]} "
               f"cells of {imported.surfaces.step:g} m, "
               f"{len(imported.terrain.scene.objects) - 1} objects, {spec.frames} scans at "
               f"{imported.source['altitude_m']} m (imported in "
               f"{time.perf_counter() - start:.1f} s)")
    folder = write_imported(imported, args.out, seed=args.seed, frames=args.frames,
                            force=args.force, progress=True, profile=profile)
    counts = json.loads((folder / SCENARIO_FILE).read_text())["counts"]
    tqdm.write(f"{spec.name}: {counts['frames']} frames, {counts['returns']} points -> "
               f"{folder} ({time.perf_counter() - start:.1f} s in all)")
    return 0


def run(args: argparse.Namespace) -> int:
    """Simulate the requested terrains, or import tiles; one summary line each."""
    profile = _profile(args)
    if any(_is_tile(n) for n in args.name):
        return _import(args, profile)
    if len(args.name) > 1:
        raise ParameterError(f"{' '.join(args.name)}: name one terrain, 'all', or terrain "
                             "tiles (.las, .laz, .pcd, .tif, .asc)")
    names = list(TERRAINS) if args.name[0] == "all" else args.name
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
