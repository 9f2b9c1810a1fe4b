"""Row 15: the ground stage on every real tile against the peer packages, same process.

For every ISPRS sample and ALS tile in ``../shared/realdata`` (none without it), process
CPU seconds (every thread) of the ground stage's default (:func:`alte.ground.filters.
filter_ground`: SMRF through pysmrf, the cloud shifted near the origin, one BLAS
thread for the inpainting solver) against the peers called directly as their authors
document them, on the same points in the same run: ``pysmrf.classify`` with SMRF's
published parameters and its own defaults otherwise, and the CSF package with its
defaults. Interleaved run by run; the median of ``repeats`` (at most 3: whole tiles).
The target: seconds a tile (at most :data:`TILE_CPU_S`; SMRF's cost follows the tile's
area more than its points: the sparse mountains cost 29 CPU s per million points, the
dense forest 2) and no slower than pysmrf called directly (ratio ``LIMITS[15]``).
"""

from __future__ import annotations

import time
import warnings
from collections.abc import Callable
from functools import partial

import numpy as np
from numpy.typing import NDArray

from alte.types import JSONDict
from bench.core import LIMITS, Context, Result
from bench.timing import interleave

__all__ = ["TILE_CPU_S", "ground_speed", "peer_csf", "peer_smrf"]

#: Most CPU seconds the ground stage may take on one shared tile.
TILE_CPU_S = 5.0


def peer_smrf(points: NDArray[np.float64]) -> NDArray[np.bool_]:
    """pysmrf as its README shows it, with SMRF's published parameters."""
    import pysmrf

    with warnings.catch_warnings():  # rasterio's own deprecation inside pysmrf: not ours
        warnings.simplefilter("ignore", PendingDeprecationWarning)
        found = pysmrf.classify(points[:, 0], points[:, 1], points[:, 2], cellsize=1.0,
                                windows=18, slope_threshold=0.15, elevation_threshold=0.5,
                                elevation_scaler=1.25)
    return np.asarray(found.is_ground, bool)


def peer_csf(points: NDArray[np.float64]) -> NDArray[np.bool_]:
    """The CSF package with its defaults, as its README shows it."""
    import CSF

    from alte.ground.filters import _quiet_stdout

    cloth = CSF.CSF()
    cloth.setPointCloud(np.ascontiguousarray(points))
    ground, objects = CSF.VecInt(), CSF.VecInt()
    with _quiet_stdout():
        cloth.do_filtering(ground, objects, exportCloth=False)
    mask = np.zeros(len(points), bool)
    mask[np.asarray(ground, dtype=np.int64)] = True
    return mask


def _cpu(funcs: dict[str, Callable[[], object]], repeats: int) -> dict[str, float]:
    """Median process CPU seconds of each callable, interleaved (after one warm-up)."""
    times: dict[str, list[float]] = {name: [] for name in funcs}
    for r, name in interleave(list(funcs), repeats + 1):
        start = time.process_time()
        funcs[name]()
        if r >= 1:
            times[name].append(time.process_time() - start)
    return {name: float(np.median(t)) for name, t in times.items()}


def ground_speed(ctx: Context) -> list[Result]:
    """Row 15 (module docstring)."""
    from alte.ground.filters import filter_ground
    from alte.lab.studies.realdata import labelled_clouds, locate

    data = locate()
    if not data.available:
        return []
    # quick: the smallest ISPRS sample (a smoke run); else every sample and tile, whole
    some = {"isprs": None, "als": None} if not ctx.config.quick else {"als": ()}
    clouds = ctx.memo("ground_clouds", lambda: labelled_clouds(data, **some))
    clouds = sorted(clouds, key=lambda c: len(c.points))[:1] if ctx.config.quick else clouds
    repeats = min(ctx.config.repeats, 3)
    out = []
    for cloud in clouds:
        pts = cloud.points
        cpu = _cpu({"ours": partial(filter_ground, pts), "pysmrf": partial(peer_smrf, pts),
                    "csf": partial(peer_csf, pts)}, repeats)
        per_million = cpu["ours"] / len(pts) * 1e6
        detail: JSONDict = {"points": len(pts), "dataset": cloud.dataset,
                            "cpu_s": cpu, "cpu_s_per_million_points": per_million,
                            "points_per_cpu_s": {k: len(pts) / max(v, 1e-9)
                                                 for k, v in cpu.items()}}
        met = cpu["ours"] <= TILE_CPU_S and cpu["ours"] <= LIMITS[15] * cpu["pysmrf"]
        out.append(Result(15, f"ground stage on {cloud.name} ({len(pts):,} points) vs pysmrf",
                          cpu["ours"], cpu["pysmrf"], "cpu s",
                          f"ratio <= {LIMITS[15]:g} and <= {TILE_CPU_S:g} cpu s a tile", met,
                          detail))
    return out
