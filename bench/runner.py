"""The benchmark suite: its rows by number, run in one process.

:data:`ROWS` maps a row number to its title and function; :func:`run_bench` runs
the selected rows in order (sharing loaded terrains and the Octomap passes) and
returns a :class:`Bench` with the machine description. A row that fails is recorded
with its error and the others still run, so one broken stage never hides the rest.
"""

from __future__ import annotations

import time
import traceback
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from datetime import UTC, datetime

from tqdm.auto import tqdm

from alte.errors import ParameterError
from alte.types import JSONDict
from bench.catalog import TITLES
from bench.clouds import cloud_stages, hausdorff_speed
from bench.core import BenchSettings, Context, Result
from bench.ground import ground_speed
from bench.lio import lio_speed
from bench.maps import batch_builds, insert_latency, octomap_memory, octomap_speed
from bench.memory import map_memory
from bench.poses import pose_speed
from bench.realterrain import real_terrain
from bench.scaling import scaling
from bench.stream import scan_peer, streaming_chain
from bench.sweep import sweep_throughput
from bench.timing import machine_info, peak_rss_bytes
from bench.wall import report_wall_time

__all__ = ["ROWS", "Bench", "run_bench", "select_rows"]

Row = Callable[[Context], list[Result]]

#: Row number -> (what it compares, the function measuring it); the titles are
#: :data:`bench.catalog.TITLES`, the registry the command line lists.
_MEASURES: dict[int, Row] = {
    1: octomap_speed, 2: octomap_memory, 3: batch_builds, 4: hausdorff_speed,
    5: insert_latency, 6: cloud_stages, 7: scaling, 8: report_wall_time, 9: map_memory,
    10: streaming_chain, 11: scan_peer, 12: pose_speed, 13: sweep_throughput,
    14: real_terrain, 15: ground_speed, 16: lio_speed,
}
ROWS: dict[int, tuple[str, Row]] = {n: (TITLES[n], fn) for n, fn in sorted(_MEASURES.items())}


@dataclass
class Bench:
    """Results of one run, the rows that failed, the machine and the settings."""

    config: BenchSettings
    results: list[Result]
    errors: dict[int, str]
    machine: JSONDict
    started: str
    seconds: float = 0.0
    row_seconds: dict[int, float] = field(default_factory=dict)

    def as_dict(self) -> JSONDict:
        """JSON-ready record (row numbers as keys are strings, as JSON has them)."""
        cfg = self.config
        return {"started": self.started, "seconds": self.seconds, "machine": self.machine,
                "config": {"quick": cfg.quick, "repeats": cfg.repeats, "warmup": cfg.warmup,
                           "frames": cfg.frames, "sizes": list(cfg.scaling_sizes),
                           "budget_s": cfg.budget_s},
                "row_seconds": {str(k): v for k, v in self.row_seconds.items()},
                "errors": {str(k): v for k, v in self.errors.items()},
                "results": [r.as_dict() for r in self.results]}


def select_rows(only: Iterable[int] | None) -> list[int]:
    """The row numbers to run (all by default); unknown numbers raise ParameterError."""
    chosen = sorted(set(only)) if only else sorted(ROWS)
    bad = [n for n in chosen if n not in ROWS]
    if bad:
        raise ParameterError(f"bench: unknown row(s) {bad}; rows are {sorted(ROWS)}")
    return chosen


def run_bench(config: BenchSettings, only: Iterable[int] | None = None) -> Bench:
    """Run the chosen rows with ``config``; failures are recorded per row, not raised."""
    rows = select_rows(only)
    ctx = Context(config)
    bench = Bench(config, [], {}, machine_info(),
                  datetime.now(UTC).isoformat(timespec="seconds"))
    t0 = time.perf_counter()
    for number in tqdm(rows, desc="bench", unit="row", disable=not config.progress):
        start = time.perf_counter()
        try:
            bench.results.extend(ROWS[number][1](ctx))
        except Exception as err:  # a broken row is reported, the others still run
            last = traceback.extract_tb(err.__traceback__)[-1]
            bench.errors[number] = (f"{type(err).__name__}: {err} "
                                    f"({last.filename}:{last.lineno})")
        bench.row_seconds[number] = time.perf_counter() - start
    bench.seconds = time.perf_counter() - t0
    bench.machine["peak_rss_gib"] = round(peak_rss_bytes() / 2**30, 2)
    bench.machine["load_avg_end"] = machine_info()["load_avg_1_5_15"]
    return bench
