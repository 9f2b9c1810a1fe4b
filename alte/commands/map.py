"""``alte map``: an input (bag, terrain folder, point file) -> a terrain map and its metrics.

Everything goes through :func:`alte.pipeline.run`, the same path as the chapters, the
sweeps and the bench: ``alte map data/sim_nav_1 --mapper alte3d --set max_res=6`` gives
the chapter 4 table's map for that terrain. ``elapsed_s`` times only the mapper's
``insert``/``build`` calls (thesis 5.2.1); ``wall_s`` the whole run.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from alte.commands.options import add_frame_options, frame_spec, parse_key_values
from alte.errors import ParameterError
from alte.export import ExportSettings, timeline_feed
from alte.export import export_map as export_mcap
from alte.fsutil import refuse_overwrite
from alte.ground.surface import OccupancySettings
from alte.mappers import Domain, Feed, check_export, export_map
from alte.pipeline import DomainPolicy, MapRun, MapSettings, open_input, run

__all__ = ["add_map_options", "add_parser", "export_options", "map_spec", "mapped",
           "parse_domain", "print_summary", "run_command"]

_SUMMARY_KEYS = ("mapper", "params", "input", "input_kind", "pose_source", "domain_policy",
                 "domain", "feed",
                 "frames", "points", "points_dropped_nonfinite", "points_dropped_crop",
                 "points_outside", "local_origin", "elapsed_s", "cpu_s", "cost", "cost_unit",
                 "wall_s", "basis_functions",
                 "occupied_cells", "memory_bytes", "metrics", "export", "mcap")


def add_map_options(p: argparse.ArgumentParser) -> None:
    """The flags that choose the map (shared by ``alte map`` and ``alte export``)."""
    p.add_argument("--mapper", required=True,
                   help="the thesis' quadtree, octomap, alte2d, alte3d or an installed plugin "
                        "(alte info --mappers lists them)")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", dest="sets",
                   help="mapper parameter (repeatable), e.g. --set kappa=0.1")
    p.add_argument("--domain", default="auto", metavar="POLICY|XMIN,YMIN[,ZMIN],SIZE",
                   help="root cell: auto (the control volume of a terrain folder, else the "
                        "data), control, data, or explicit numbers")
    p.add_argument("--feed", choices=[f.value for f in Feed], default=None,
                   help="insert frame by frame, or build once on the merged cloud (default: "
                        "the mapper's protocol: Quadtree batch, the others frames)")
    p.add_argument("--cache", type=Path, default=None, metavar="DIR",
                   help="keep the registered frames in DIR for the next run of this input")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--timeline", type=int, default=None, metavar="N",
                   help="with --mcap: write the map every N mapped scans, stamped with the "
                        "scan's time (the map as it grows; batch feeds switch to frames)")
    p.add_argument("--occupancy-set", action="append", default=[], metavar="KEY=VALUE",
                   dest="occupancy_sets",
                   help="with --mcap: landing criterion of the occupancy grids (repeatable): "
                        + "; ".join(f"{k}: {v}" for k, v in OccupancySettings.help().items())
                        + "; defaults: " + ", ".join(
                            f"{k}={v}" for k, v in OccupancySettings().as_dict().items()))


def add_parser(subparsers: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register ``alte map``."""
    p = subparsers.add_parser(
        "map", help="build a terrain map from a bag, a terrain folder or a point cloud file",
        description="Build a map with one of the mappers (quadtree, octomap, alte2d, alte3d, "
                    "or a plugin's) "
                    "through the pipeline: read, register, crop, down-sample, map. Values that "
                    "start with '-' need '=': --origin=-1,0,2.")
    add_frame_options(p, origin=True)
    add_map_options(p)
    p.add_argument("--metrics", action="store_true",
                   help="also measure the map: HD/MHD against the registered cloud and, for "
                        "a terrain folder, the ground-truth metrics")
    p.add_argument("--export", type=Path, default=None, metavar="FILE",
                   help="write the cells (.npz) or an OctoMap tree (.bt, octomap only)")
    p.add_argument("--mcap", type=Path, default=None, metavar="FILE",
                   help="also write a ROS 2 MCAP for Foxglove / RViz (see alte export)")
    p.add_argument("--force", action="store_true",
                   help="overwrite --export / --mcap if they exist")
    p.set_defaults(func=run_command)


def parse_domain(text: str) -> Domain | DomainPolicy:
    """``--domain``: a policy name or ``xmin,ymin[,zmin],size``."""
    names = {p.value: p for p in DomainPolicy}
    if text.strip().lower() in names:
        return names[text.strip().lower()]
    try:
        return Domain.parse(text)
    except ParameterError as err:
        raise ParameterError(f"--domain {text!r}: expected {', '.join(names)} or numbers "
                             "xmin,ymin[,zmin],size with size > 0") from err


def _summary(result: MapRun, metrics: bool) -> dict[str, object]:
    out = result.summary()
    if metrics:
        from alte.metrics.maps import measure_map
        from alte.metrics.timing import Timing

        source = open_input(result.info.input)
        assert result.cloud is not None  # run(..., cloud=True) kept it for the metrics
        timing = Timing.of([result.elapsed_s], [result.cpu_s])  # one run, no spread
        out["metrics"] = measure_map(result.mapper, result.cloud, elapsed_s=timing,
                                     truth=source.ground_truth()).as_dict()
    return out


def print_summary(summary: dict[str, object], as_json: bool) -> None:
    if as_json:
        print(json.dumps(summary, sort_keys=True, default=str))
        return
    for key in _SUMMARY_KEYS:
        if key in summary:
            print(f"{key}: {summary[key]}")


def map_spec(args: argparse.Namespace) -> MapSettings:
    """The :class:`MapSettings` of the parsed flags, parameters checked before any read."""
    return MapSettings(args.mapper, parse_key_values(args.sets, "--set"), parse_domain(args.domain),
                   Feed(args.feed) if args.feed else None)


def mapped(args: argparse.Namespace, mcap: Path | None, options: ExportSettings,
           cloud: bool = False, spec: MapSettings | None = None) -> tuple[MapRun, dict[str, int]]:
    """Run the map as ``spec`` says (default: the flags'; and write the MCAP when ``mcap``
    is given); message counts per topic."""
    spec, frames = spec or map_spec(args), frame_spec(args)
    try:
        timeline_feed(spec, options)
    except ParameterError as err:
        raise ParameterError(f"--timeline {options.timeline} with --feed {args.feed}: {err}; "
                             "use --feed frames") from err
    source = open_input(args.input)
    if mcap is None:
        return run(source, spec, frames, cache=args.cache, cloud=cloud,
                   progress=not args.json), {}
    return export_mcap(source, mcap, spec, frames, options=options, cache=args.cache,
                      overwrite=args.force, progress=not args.json)


def export_options(args: argparse.Namespace, mcap: Path | None) -> ExportSettings:
    """``--timeline``, ``--occupancy-set`` and the MCAP flags, checked (and the target
    refused) before the read."""
    if mcap is None:
        for flag, given in (("--timeline", args.timeline is not None),
                            ("--occupancy-set", bool(args.occupancy_sets))):
            if given:
                raise ParameterError(f"{flag} shapes the map written into --mcap FILE; add it")
        return ExportSettings()
    if mcap.suffix.lower() != ".mcap":
        raise ParameterError(f"--mcap {mcap}: the file name must end in .mcap")
    try:
        rule = OccupancySettings.parse(parse_key_values(args.occupancy_sets, "--occupancy-set"))
    except ParameterError as err:
        raise ParameterError(f"--occupancy-set: {err}") from err
    try:
        options = ExportSettings(args.timeline, scans=not getattr(args, "no_scans", False),
                                all_cells=getattr(args, "all_cells", False), surface=rule)
    except ParameterError as err:
        raise ParameterError(f"--timeline: {err}") from err
    refuse_overwrite(mcap, args.force)
    return options


def run_command(args: argparse.Namespace) -> int:
    """Build the map, print the summary, export when asked."""
    options = export_options(args, args.mcap)
    spec = map_spec(args)
    if args.export is not None:
        check_export(args.export, spec.cls, args.force)
    result, topics = mapped(args, args.mcap, options, cloud=args.metrics, spec=spec)
    summary = _summary(result, args.metrics)
    if topics:
        summary["mcap"] = {"file": str(args.mcap), "messages": topics}
    if args.export is not None:
        export_map(result.mapper, args.export, args.force, np.asarray(result.info.local_origin))
        summary["export"] = str(args.export)
    print_summary(summary, args.json)
    return 0
