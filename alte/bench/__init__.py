"""Performance benchmark: our stages against real peers, as ratios.

``alte bench`` (or ``make bench``) runs :data:`ROWS` and writes ``reports/bench.md``,
``reports/bench.json`` and ``reports/bench_scaling.png``. Every figure is the median
of at least five repeats after a warm-up, ours interleaved with its peer in one
process. The machinery lives here (importable by :mod:`alte.commands.bench`);
``bench/README.md`` explains the rows and what the profiles showed.
"""

from alte.bench.core import LIMITS, BenchConfig, Context, Result
from alte.bench.output import render_markdown, write_outputs
from alte.bench.runner import ROWS, Bench, run_bench, select_rows
from alte.bench.timing import Sample, fit_exponent, machine_info, measure
from alte.bench.workload import Workload, load_workload, tile_points

__all__ = ["LIMITS", "ROWS", "Bench", "BenchConfig", "Context", "Result", "Sample", "Workload",
           "fit_exponent", "load_workload", "machine_info", "measure", "render_markdown",
           "run_bench", "select_rows", "tile_points", "write_outputs"]
