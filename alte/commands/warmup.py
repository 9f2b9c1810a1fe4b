"""``alte warmup``: compile the mappers' kernels once, so no flight pays for it.

The mappers' hot loops are numba functions compiled on first use and cached beside
the package (``__pycache__``). The first ``alte map`` after an install (or after an
update of the package) would otherwise spend tens of seconds compiling inside its first
scans, far over a 100 ms sensor period. This command maps a two-scan simulated flight
with every mapper and feed, through the same pipeline as ``alte map``, and measures HD/MHD
once (the grid search of ``alte map --metrics``, about 10 s to compile), so each kernel is
compiled and written to the cache; later processes load it in milliseconds. The 2D maps
also build a synthetic cloud of ``CLOUD_MIN`` points, writeable and read-only: a whole
cloud takes kernels a scan never reaches (the Quadtree's tree walk on every thread), and
numba compiles a kernel once per array type.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import numpy as np

from alte._numba import CLOUD_MIN
from alte.mappers import Feed, Mapper, make_mapper, registry
from alte.metrics.hausdorff import hausdorff
from alte.pipeline import MapSettings, run
from alte.sim import ensure_terrain

__all__ = ["add_parser", "run_warmup", "warm_kernels"]

#: The flight mapped: short, 3D (every mapper applies) and quick to simulate.
TERRAIN, SCANS = "sim_nav_1", 2


def add_parser(subparsers: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register ``alte warmup``."""
    p = subparsers.add_parser(
        "warmup",
        help="compile the mappers' kernels into the package cache (once per install)",
        description="Map a two-scan simulated flight with every mapper, frame by frame and "
        "in one batch, so numba compiles and caches every kernel now instead of during the "
        "first scans of a real flight.",
    )
    p.set_defaults(func=run_warmup)


def _touch(mapper: Mapper) -> int:
    """Call what the map and its exports use after mapping; returns the cell count."""
    mapper.corners()
    mapper.cell_counts()
    return len(mapper.cells().centers)


def warm_kernels() -> dict[str, int]:
    """Map the flight with every mapper (plugins included) and feed; returns
    ``mapper/feed -> cells``."""
    cells: dict[str, int] = {}
    mappers = registry.classes()
    with tempfile.TemporaryDirectory(prefix="alte-warmup-") as tmp:
        folder = ensure_terrain(TERRAIN, Path(tmp), frames=SCANS)
        for kind in mappers:
            for feed in Feed:
                result = run(folder, MapSettings(kind, feed=feed))
                cells[f"{kind.name}/{feed.value}"] = _touch(result.mapper)
    corners = result.mapper.corners()
    hausdorff(corners, corners[::3])
    cloud = np.random.default_rng(0).uniform((0.0, 0.0, -1.0), (50.0, 50.0, 3.0), (CLOUD_MIN, 3))
    for kind in mappers:
        if kind.dims == 2:
            for writeable in (True, False):  # a cached, memory-mapped cloud is read-only
                cloud.setflags(write=writeable)
                mapper = make_mapper(kind)
                mapper.build(cloud)
            cells[f"{kind.name}/cloud"] = _touch(mapper)
    return cells


def run_warmup(args: argparse.Namespace) -> int:
    """Entry point of ``alte warmup``."""
    start = time.perf_counter()
    cells = warm_kernels()
    runs = ", ".join(f"{run} {count}" for run, count in cells.items())
    mappers = len({run.split("/")[0] for run in cells})
    print(f"compiled and cached the kernels of {mappers} mappers in "
          f"{time.perf_counter() - start:.1f} s; cells per run: {runs}")
    return 0
