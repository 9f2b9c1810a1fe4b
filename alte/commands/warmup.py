"""``alte warmup``: compile alte's numba kernels once, so no flight or report pays for it.

The mappers' hot loops are numba functions compiled on first use and cached beside
the package (``__pycache__``). The first ``alte map`` after an install (or after an
update of the package) would otherwise spend tens of seconds compiling inside its first
scans, far over a 100 ms sensor period. This command maps a two-scan simulated flight
with every mapper and feed, through the same pipeline as ``alte map``, and measures HD/MHD
once (the grid search of ``alte map --metrics``, about 10 s to compile), so each kernel is
compiled and written to the cache; later processes load it in milliseconds. The 2D maps
also build a synthetic cloud of ``CLOUD_MIN`` points, writeable and read-only: a whole
cloud takes kernels a scan never reaches (the Quadtree's tree walk on every thread), and
numba compiles a kernel once per array type. Each map is then measured against the
terrain's truth (the truth metrics' cell lookup and free-space kernels), painted on a raster
(the obstacle study's), and the kernels no flight reaches (a PCD file's decompression, a
contiguous x/y lookup) are called once each. ``alte report`` runs this first, in its own
process while the terrains are simulated, so its notebooks and their workers load every
kernel instead of compiling it side by side (tests/commands/test_warmup.py checks that
every kernel of alte and its plugins is compiled here).
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import numpy as np

from alte._numba import CLOUD_MIN
from alte.io.points.lzf import lzf_decompress
from alte.lab.studies.landing.raster import RasterGeometry
from alte.lab.studies.obstacles import map_raster
from alte.mappers import Feed, Mapper, make_mapper, registry
from alte.mappers.octomap.cost import scan_cost
from alte.mappers.quad.quadgrid import Square
from alte.metrics.hausdorff import hausdorff
from alte.metrics.maps import TruthSettings, measure_map
from alte.pipeline import MapRun, MapSettings, open_input, run
from alte.sim import ensure_terrain

__all__ = ["add_parser", "run_warmup", "warm_kernels"]

#: The flight mapped: short, 3D (every mapper applies) and quick to simulate.
TERRAIN, SCANS = "sim_nav_1", 2
#: Truth metrics on a coarse grid and few samples: the kernels, not the numbers, matter here.
TRUTH = TruthSettings(n_samples=500, grid_step=2.0)
#: A raster of a few pixels for the obstacle study's painting kernel.
RASTER = RasterGeometry((0.0, 0.0), 10.0, (4, 4))


def add_parser(subparsers: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register ``alte warmup``."""
    p = subparsers.add_parser(
        "warmup",
        help="compile the mappers' kernels into the package cache (once per install)",
        description="Map a two-scan simulated flight with every mapper, frame by frame and "
        "in one batch, so numba compiles and caches every kernel now instead of during the "
        "first scans of a real flight.",
    )
    p.add_argument("--part", type=_part, default=(1, 1), metavar="K/N",
                   help="compile the K-th of N parts (the mappers dealt round-robin): "
                   "alte report runs the parts side by side (default: all, 1/1)")
    p.set_defaults(func=run_warmup)


def _part(text: str) -> tuple[int, int]:
    """``K/N`` as (K, N) with 1 <= K <= N; argparse names ``--part`` in the error."""
    k, _, n = text.partition("/")
    if not (k.isdigit() and n.isdigit() and 1 <= int(k) <= int(n)):
        raise argparse.ArgumentTypeError(f"expected K/N with 1 <= K <= N, got {text!r}")
    return int(k), int(n)


def _touch(mapper: Mapper) -> int:
    """Call what the map and its exports use after mapping; returns the cell count."""
    mapper.corners()
    mapper.cell_counts()
    return len(mapper.cells().centers)


def _measure(result: MapRun, folder: Path) -> None:
    """The map's metrics against its cloud and the terrain's truth, and its raster."""
    truth = open_input(folder).ground_truth()
    assert result.cloud is not None and truth is not None  # a simulated terrain, cloud kept
    measure_map(result.mapper, result.cloud, elapsed_s=0.0, truth=truth, options=TRUTH)
    map_raster(result.mapper.cells(), result.mapper.dims, RASTER, 0.5)


def _others() -> None:
    """Kernels no map of the flight reaches: a PCD body's decompression (a read-only
    buffer: the file's bytes), the x/y lookup of a contiguous (N, 2) array and the ray
    count of Octomap's reference backend (pyoctomap), the LIO's local map."""
    literal_run = np.frombuffer(bytes([3, 1, 2, 3, 4]), np.uint8)
    lzf_decompress(literal_run, 4)
    Square(0.0, 0.0, 1.0).locate(np.full((4, 2), 0.5), 2)
    scan_cost(np.ones((4, 3), np.float32), np.zeros(3, np.float32), 0.1, 10.0)
    _lio_map()


def _lio_map() -> None:
    """The LIO's local map: a packed tree, a few rows appended under a second one, and the
    plane fits of a query (the fits' kernel and the merge of both trees' neighbours),
    asked again from points moved a little (the neighbours kept between iterations)."""
    from alte.registration.localmap import LocalMap

    ground = np.random.default_rng(0).uniform((-5.0, -5.0, 0.0), (5.0, 5.0, 0.01), (400, 3))
    local = LocalMap(0.25, 50.0)
    local.add(ground[:380], np.zeros(3))
    local.add(ground[380:], np.zeros(3))
    local.planes(ground[:8], 1.0, 5, (20, 3.0))
    local.planes(ground[:8] + 1e-3, 1.0, 5, (20, 3.0))


def warm_kernels(part: tuple[int, int] = (1, 1)) -> dict[str, int]:
    """Map the flight with every mapper (plugins included) and feed; returns
    ``mapper/feed -> cells``. ``part = (K, N)``: the K-th of N round-robin shares of the
    mappers (the first also compiles the kernels no map reaches)."""
    cells: dict[str, int] = {}
    mappers = registry.classes()[part[0] - 1::part[1]]
    with tempfile.TemporaryDirectory(prefix="alte-warmup-") as tmp:
        folder = ensure_terrain(TERRAIN, Path(tmp), frames=SCANS)
        for kind in mappers:
            for feed in Feed:
                result = run(folder, MapSettings(kind, feed=feed), cloud=True)
                cells[f"{kind.name}/{feed.value}"] = _touch(result.mapper)
            _measure(result, folder)  # one feed: the metrics' kernels see the cells alone
    if part[0] == 1:
        corners = result.mapper.corners()
        hausdorff(corners, corners[::3])
        _others()
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
    cells = warm_kernels(args.part)
    runs = ", ".join(f"{run} {count}" for run, count in cells.items())
    mappers = len({run.split("/")[0] for run in cells})
    share = "" if args.part == (1, 1) else f" (part {args.part[0]} of {args.part[1]})"
    print(f"compiled and cached the kernels of {mappers} mappers{share} in "
          f"{time.perf_counter() - start:.1f} s; cells per run: {runs}")
    return 0
