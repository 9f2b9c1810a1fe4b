"""``alte bench``: run the performance benchmark and write reports/bench.{md,json}.

The benchmark lives outside the package, in the ``bench/`` folder of a source checkout
(as rosbags keeps its benchmarks): this command finds it beside the ``alte`` it runs.
"""

from __future__ import annotations

import argparse
import sys
import textwrap
from pathlib import Path

from alte.errors import AlteError
from alte.paths import REPO_ROOT


def _find_bench(checkout: Path = REPO_ROOT) -> None:
    """Make the checkout's ``bench`` package importable, or say why it cannot be."""
    if not (checkout / "bench" / "__init__.py").is_file():
        raise AlteError(f"alte bench runs from a source checkout: no bench/ folder beside "
                        f"{checkout / 'alte'} (clone the repository and run it there)")
    if str(checkout) not in sys.path:
        sys.path.insert(0, str(checkout))


_find_bench()
from bench.catalog import TITLES, describe  # noqa: E402  (after the checkout is on the path)

__all__ = ["add_parser", "run"]


def _rows(text: str) -> list[int]:
    try:
        return [int(v) for v in text.split(",") if v.strip()]
    except ValueError as err:
        raise argparse.ArgumentTypeError(f"--only {text!r}: expected row numbers like 1,3") from err


def _sizes(text: str) -> tuple[int, ...]:
    try:
        return tuple(int(float(v)) for v in text.split(",") if v.strip())
    except ValueError as err:
        raise argparse.ArgumentTypeError(f"--sizes {text!r}: expected counts like 1e4,1e5") from err


def add_parser(subparsers: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register ``bench``; its help lists the rows of the benchmark's own registry."""
    first, last = min(TITLES), max(TITLES)
    parser = subparsers.add_parser(
        "bench", help="run the performance benchmark",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description=textwrap.fill(
            "Time our stages beside their peers (pyoctomap, open3d, numpy.argsort, "
            "kiss-icp, ...) and write reports/bench.md, bench.json and bench_scaling.png.")
        + "\n\nThe rows:\n\n" + describe())
    parser.add_argument("--quick", action="store_true",
                        help="tiny inputs (a few simulated scans): a smoke run in seconds")
    parser.add_argument("--only", type=_rows, default=None, metavar="ROWS",
                        help=f"comma-separated row numbers to run (default: all, {first}-{last}: "
                             "the rows above)")
    parser.add_argument("--repeats", type=int, default=5, help="timed repeats (default 5)")
    parser.add_argument("--warmup", type=int, default=1, help="discarded warm-up runs")
    parser.add_argument("--frames", type=int, default=None,
                        help="sim_nav_1 scans for rows 1, 2, 4 (default all; row 5 always all)")
    parser.add_argument("--sizes", type=_sizes, default=(), metavar="N,N,...",
                        help="row 7 point counts (default 1e4,1e5,1e6,1e7)")
    parser.add_argument("--budget", type=float, default=60.0, metavar="S",
                        help="row 7 skips a size predicted to take longer than S per run")
    parser.add_argument("--data", type=Path, default=Path("data"),
                        help="terrain folder (default data/)")
    parser.add_argument("--reports", type=Path, default=Path("reports"),
                        help="output folder (default reports/)")
    parser.add_argument("--no-progress", action="store_true", help="hide progress bars")
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Run the benchmark, write its outputs, print the table; 1 when a row failed."""
    from bench.core import BenchSettings
    from bench.output import render_markdown, write_outputs
    from bench.runner import run_bench, select_rows

    config = BenchSettings(quick=args.quick, repeats=args.repeats, warmup=args.warmup,
                         frames=args.frames, sizes=args.sizes, budget_s=args.budget,
                         data_dir=args.data, reports_dir=args.reports,
                         progress=not args.no_progress)
    rows = select_rows(args.only)
    bench = run_bench(config, rows)
    paths = write_outputs(bench, args.reports)
    print(render_markdown(bench))
    print("wrote " + ", ".join(str(p) for p in paths.values()))
    return 1 if bench.errors else 0
