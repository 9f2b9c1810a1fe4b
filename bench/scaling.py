"""Row 7: how each mapper and the Hausdorff metrics scale from 10^4 to 10^7 points.

Inputs are the terrains' own clouds, evenly subsampled below their size and tiled
side by side above it (:func:`bench.workload.tile_points`), so density and
structure stay those of the terrain. Octomap gets whole scans with their sensor
origins (runs of equal origin = one scan each, as ``build`` defines), so rays keep
their real length and scans their real size. The exponent is the slope of a log-log fit; exact
n log n over the same sizes gives the bar (plus 0.1 for timing noise). A size whose
run is predicted to exceed ``budget_s`` (from the last size and the slope so far)
is skipped and reported as such.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np
from tqdm.auto import tqdm

from alte.lab.studies.thesis.numbers import mapper_params
from alte.types import JSONDict
from bench.core import Context, Result
from bench.maps import NAV, bench_params, cloud_mappers, terrain_of
from bench.timing import fit_exponent, measure, nlogn_exponent, peak_rss_bytes
from bench.workload import Points, Scan, tile_points

__all__ = ["EXPONENT_SLACK", "predicted_seconds", "scaling", "scaling_cases", "whole_scans"]

#: Allowed excess of the fitted exponent over n log n's (timing noise on a shared machine).
EXPONENT_SLACK = 0.1

Case = Callable[[int], tuple[int, Callable[[], object]]]


def whole_scans(frames: Sequence[Scan], n: int) -> tuple[Points, Points]:
    """About ``n`` points as whole scans with per-point origins: evenly spaced scans of the
    mission below its size, the whole mission tiled side by side above it."""
    sizes = np.array([len(p) for p, _ in frames])
    total = int(sizes.sum())
    if n > total:
        pts = np.vstack([p for p, _ in frames])
        origins = np.repeat(np.array([o for _, o in frames]), sizes, axis=0)
        tiled, tiled_origins = tile_points(pts, math.ceil(n / total) * total, origins)
        return tiled, tiled_origins
    k = max(1, round(len(frames) * n / total))
    pick = np.unique(np.round(np.linspace(0, len(frames) - 1, k)).astype(int))
    chosen = [frames[i] for i in pick]
    return (np.vstack([p for p, _ in chosen]),
            np.repeat(np.array([o for _, o in chosen]), [len(p) for p, _ in chosen], axis=0))


def scaling_cases(ctx: Context) -> dict[str, Case]:
    """Name -> (size -> actual size, the timed call); inputs are built untimed.

    Octomap gets whole scans (:func:`whole_scans`): thinning every scan instead would
    keep the 569 per-scan costs fixed and hide how the map's growth costs.
    """
    from alte.mappers import Mapper, Octomap, make_mapper
    from alte.metrics import hausdorff

    def cloud_build(cls: type[Mapper]) -> Case:
        def make(n: int) -> tuple[int, Callable[[], object]]:
            (pts,) = tile_points(ctx.workload(terrain_of(cls)).cloud, n)
            params = bench_params(cls)
            return len(pts), lambda: make_mapper(cls, params).build(pts)
        return make

    def octomap(n: int) -> tuple[int, Callable[[], object]]:
        pts, origins = whole_scans(ctx.workload(NAV).frames, n)
        params = mapper_params(NAV)["octomap"]
        return len(pts), lambda: make_mapper(Octomap, params).build(pts, origins)

    def metrics(n: int) -> tuple[int, Callable[[], object]]:
        (pts,) = tile_points(ctx.workload(NAV).cloud, n)
        return len(pts), lambda: hausdorff(pts, pts[::4])

    return {"octomap": octomap, **{c.name: cloud_build(c) for c in cloud_mappers()},
            "hausdorff": metrics}


def predicted_seconds(sizes: list[int], seconds: list[float], n: int) -> float:
    """Seconds expected at ``n`` from the last timing and the slope so far (>= 1)."""
    slope = max(1.0, fit_exponent(sizes, seconds)) if len(sizes) >= 2 else 1.0
    predicted: float = seconds[-1] * (n / sizes[-1]) ** slope
    return predicted


def _one_case(ctx: Context, name: str, make: Case) -> Result:
    cfg = ctx.config
    sizes: list[int] = []
    seconds: list[float] = []
    skipped: dict[int, float] = {}
    rss: dict[int, int] = {}
    for n in cfg.scaling_sizes:
        if sizes and (guess := predicted_seconds(sizes, seconds, n)) > cfg.budget_s:
            skipped[n] = guess
            continue
        size, call = make(n)
        if sizes and size <= sizes[-1]:
            continue  # whole scans can round two sizes to the same input
        sample = measure({name: call}, cfg.repeats, cfg.warmup)[name]
        sizes.append(size)
        seconds.append(sample.median)
        rss[n] = peak_rss_bytes()
    exponent = fit_exponent(sizes, seconds) if len(sizes) >= 2 else float("nan")
    bar = nlogn_exponent(sizes) if len(sizes) >= 2 else float("nan")
    detail: JSONDict = {"sizes": sizes, "seconds": seconds,
                                  "peak_rss_bytes": {str(n): b for n, b in rss.items()},
                                  "skipped_predicted_s": {str(n): s for n, s in skipped.items()}}
    met = bool(exponent <= bar + EXPONENT_SLACK) if len(sizes) >= 2 else None
    span = f"{sizes[0]:.0e}..{sizes[-1]:.0e}" if sizes else "none"
    return Result(7, f"{name} scaling, n = {span}", exponent, bar, "exponent",
                  f"exponent <= n log n's + {EXPONENT_SLACK}", met, detail)


def scaling(ctx: Context) -> list[Result]:
    """Row 7: fitted exponents of every mapper's build and of HD/MHD."""
    cases = scaling_cases(ctx)
    return [_one_case(ctx, name, make)
            for name, make in tqdm(cases.items(), desc="scaling", unit="case",
                                   disable=not ctx.config.progress, leave=False)]
