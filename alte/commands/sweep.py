"""``alte sweep SPEC.yaml``: run a parameter grid (serial or Dask), append Parquet rows."""

from __future__ import annotations

import argparse
import shlex
import time
from datetime import UTC, datetime
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from alte.lab.studies.sweep import SweepResult, SweepSpec

__all__ = ["add_parser", "run"]


def add_parser(subparsers: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register ``sweep``."""
    parser = subparsers.add_parser(
        "sweep", help="run a grid of terrains x mappers x parameters (resumable, Dask)",
        description="Run every run of a YAML sweep spec that its Parquet output folder does not "
                    "hold yet (finished runs are skipped, so an interrupted sweep resumes), one "
                    "row of metrics per run. Default: a local Dask cluster.")
    parser.add_argument("spec", type=Path, help="sweep spec (YAML), e.g. notebooks/sweeps/"
                        "small.yaml")
    parser.add_argument("--scheduler", default="local", metavar="ADDRESS",
                        help="'local' (a LocalCluster, default), 'serial'/'none' (in-process) "
                             "or a running scheduler's address, e.g. tcp://host:8786")
    parser.add_argument("--workers", type=int, default=2,
                        help="worker processes of the local cluster (default 2)")
    parser.add_argument("--out", type=Path, default=None,
                        help="Parquet dataset folder (default: the spec's output)")
    parser.add_argument("--frames", type=int, default=None,
                        help="scans per terrain, overriding the spec's frames")
    parser.add_argument("--seeds", type=int, nargs="+", default=None, metavar="SEED",
                        help="simulation seeds, overriding the spec's seed(s)")
    parser.add_argument("--data", type=Path, default=None,
                        help="terrain folder, overriding the spec's data_dir")
    parser.add_argument("--evidence", type=Path, default=None, metavar="FOLDER",
                        help="once every run is done, write the grid's claims, equal-size and "
                             "equal-fidelity tables, fronts and provenance there (the "
                             "whole-mission evidence make report reads, e.g. "
                             "notebooks/sweeps/tradeoff-full)")
    parser.add_argument("--plugins", action="store_true",
                        help="add every installed plugin mapper the spec does not list, with "
                             "its own settings grid (alte info --mappers lists them)")
    parser.add_argument("--no-progress", action="store_true", help="hide progress bars")
    parser.set_defaults(func=run)


def _command(args: argparse.Namespace) -> str:
    """The command line that reproduces ``args``."""
    words = ["alte", "sweep", str(args.spec), "--scheduler", args.scheduler]
    if args.scheduler == "local":
        words += ["--workers", str(args.workers)]
    for flag, value in (("--frames", args.frames), ("--data", args.data), ("--out", args.out),
                        ("--evidence", args.evidence)):
        if value is not None:
            words += [flag, str(value)]
    if args.seeds is not None:
        words += ["--seeds", *map(str, args.seeds)]
    if args.plugins:
        words.append("--plugins")
    return shlex.join(words)


def _evidence(args: argparse.Namespace, spec: SweepSpec, result: SweepResult, started: str,
              seconds: float) -> None:
    from alte.lab.machine import machine_info
    from alte.lab.studies.missions import Provenance, git_commit, write_mission_evidence
    from alte.lab.studies.tradeoff.grid import grid_of

    grid = grid_of(spec, result, seconds)
    provenance = Provenance(
        command=_command(args), commit=git_commit(), spec=str(args.spec), runs=grid.runs,
        ran=result.ran, frames=spec.frames, seeds=list(spec.seeds), cpu_s=round(grid.cpu_s, 1),
        wall_s=round(seconds, 1), started=started,
        finished=datetime.now(UTC).isoformat(timespec="seconds"), machine=machine_info())
    folder = write_mission_evidence(grid.table, args.evidence, provenance)
    print(f"evidence of {grid.runs} runs written to {folder}")


def run(args: argparse.Namespace) -> int:
    """Run the sweep and print a summary; 1 when a run failed (rerun to retry it)."""
    from alte.lab.studies.sweep import load_spec, override, run_sweep

    spec = load_spec(args.spec)
    if args.frames is not None:
        spec = override(spec, frames=args.frames)
    if args.data is not None:
        spec = override(spec, data_dir=str(args.data))
    if args.seeds is not None:
        spec = override(spec, seeds=args.seeds)
    if args.plugins:
        spec = override(spec, plugins=True)
    started, start = datetime.now(UTC).isoformat(timespec="seconds"), time.perf_counter()
    result = run_sweep(spec, scheduler=args.scheduler, workers=args.workers, output=args.out,
                       progress=not args.no_progress)
    seconds = time.perf_counter() - start
    for failed, message in result.failed:
        print(f"failed: {failed.terrain} {failed.mapper} {dict(failed.params)}: {message}")
    print(f"sweep {spec.name}: {result.ran} run, {result.skipped} already done, "
          f"{len(result.failed)} failed; {len(result.table)} rows in {result.output}")
    if result.failed:
        if args.evidence is not None:
            print(f"evidence not written to {args.evidence}: rerun to retry the failed runs")
        return 1
    if args.evidence is not None:
        _evidence(args, spec, result, started, seconds)
    return 0
