"""``alte report``: run every notebook into a new report folder (``make report``)."""

from __future__ import annotations

import argparse
from pathlib import Path

from alte.errors import ParameterError
from alte.lab.report import PLAN, build_plan, load_plan, parse_param, run_report
from alte.lab.report.warm import start_warmup
from alte.paths import REPO_ROOT

__all__ = ["add_parser", "run"]


def add_parser(subparsers: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register ``alte report``."""
    p = subparsers.add_parser(
        "report", help="execute the notebooks and build reports/index.html",
        description="Compile alte's numba kernels (alte warmup) while simulating missing "
                    "terrains, execute every notebook with papermill, write "
                    "HTML and an index into reports/runs/<UTC stamp>/ and point reports/latest "
                    "at it. Exits 1 when a notebook failed.")
    p.add_argument("--quick", action="store_true",
                   help="small defaults and fewer terrains (minutes instead of hours)")
    p.add_argument("--only", nargs="+", default=[], metavar="NAME",
                   help="run only these runs or notebooks (e.g. ch4_terrain, ch4_sim_nav_1)")
    p.add_argument("--out", type=Path, default=Path("reports"), help="reports folder")
    p.add_argument("--data", type=Path, default=Path("data"), help="terrain data folder")
    p.add_argument("--param", action="append", default=[], metavar="NAME=VALUE",
                   help="override a notebook parameter in every notebook declaring it")
    p.add_argument("--jobs", type=int, default=1, help="notebooks executed in parallel")
    p.add_argument("--notebooks", type=Path, default=REPO_ROOT / "notebooks",
                   help="notebook folder (default: the repository's)")
    p.add_argument("--plan", type=Path, default=None,
                   help="JSON plan replacing the built-in one (list of Entry objects)")
    p.add_argument("--no-warmup", action="store_true",
                   help="do not compile alte's kernels first (alte warmup; a few seconds when "
                        "they are cached): for notebooks that do not map")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Plan, execute, print a summary; 1 if any notebook failed."""
    if args.jobs < 1:
        raise ParameterError(f"--jobs {args.jobs}: must be at least 1")
    entries = load_plan(args.plan) if args.plan else PLAN
    overrides = dict(parse_param(text) for text in args.param)
    runs = build_plan(entries, quick=args.quick, notebooks_dir=args.notebooks, only=args.only,
                      overrides=overrides)
    report = run_report(runs, args.out, args.data, quick=args.quick, jobs=args.jobs,
                        warmup=None if args.no_warmup else start_warmup)
    for result in report.results:
        line = f"{result.status:8s} {result.seconds:7.1f} s  {result.name}"
        print(line + (f"  ({result.error})" if result.error else ""))
    for problem in report.problems:
        print(f"problem: {problem}")
    failed = report.failed
    print(f"{len(report.results) - len(failed)}/{len(report.results)} notebooks ok in "
          f"{report.seconds:.1f} s; report: {report.run_dir / 'index.html'}")
    if failed:
        print(f"FAILED: {', '.join(r.name for r in failed)}")
    return 1 if failed else 0
