"""Rows 10 and 11: the whole streaming chain against the sensor, and a UFOMap-based peer.

Row 10 times ``alte map BAG`` as the pipeline runs it (:func:`alte.pipeline.run` on the
terrain's bag: every scan read, registered with its pose and inserted, frame by frame;
with a bag's default frame options, i.e. no crop and no grid average, and the domain
from the data, which costs a first pass over the bag for the mappers that take one),
from the first byte read to the last map update. The peer is the mission's own
duration (scans x their period): ``wall / mission <= 0.1`` is 10x faster than real
time. Each mapper runs with the terrain's chapter 4 parameters where the thesis gives
them (its defaults otherwise); runs of all mappers of a terrain alternate round by
round. The row runs on one core: every thread of the process is pinned to one CPU
(:func:`bench.timing.one_core`), and each run's process CPU time is kept beside
its wall time (CPU <= wall shows that no second core helped). Per-frame latency
(reading, registering, inserting: ``MapRun.log.latency_s``) is reported beside the
sensor's 100 ms.

Row 11 is the peer beyond liboctomap: DUFOMap's scan integration (Python bindings of
DUFOMap, built on UFOMap: rays cast into an octree at the same 0.2 m, on one thread as
the native Octomap) against the native Octomap on the same scans, fresh maps,
alternating pass by pass. The maps differ in kind (DUFOMap keeps seen / void / hit
states for dynamic-point removal, not OctoMap's log-odds), so only the time is compared.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray
from tqdm.auto import tqdm

from alte.types import JSONDict
from bench.core import LIMITS, Context, Result
from bench.maps import LAN, NAV, ROTATION_S, interleaved_passes
from bench.timing import interleave, one_core
from bench.workload import QUICK_FRAMES, Points, Scan, workload_dir

if TYPE_CHECKING:
    from alte.pipeline import MapRun, MapSettings

__all__ = ["UfoPeer", "mission_seconds", "scan_peer", "streaming_chain"]


def mission_seconds(stamps_ns: NDArray[np.int64]) -> float:
    """Sensor time a run covers: its scans times their (median) period."""
    if len(stamps_ns) < 2:
        return ROTATION_S * len(stamps_ns)
    return float(len(stamps_ns) * np.median(np.diff(stamps_ns)) / 1e9)


def _bag(ctx: Context, terrain: str) -> Path:
    from alte.pipeline import open_input
    from alte.sim import ensure_terrain

    cfg = ctx.config
    folder = ensure_terrain(terrain, workload_dir(cfg.data_dir, cfg.quick),
                            frames=QUICK_FRAMES if cfg.quick else None)
    source = open_input(folder)
    assert source.bag is not None, "a terrain folder names its bag"
    return source.bag


def _one_run(bag: Path, spec: MapSettings) -> tuple[float, float, MapRun]:
    """Wall and process CPU seconds of one ``run`` of ``spec`` on ``bag``, and the run."""
    from alte.pipeline import run

    start, used = time.perf_counter(), time.process_time()
    result = run(bag, spec)
    return time.perf_counter() - start, time.process_time() - used, result


def _quantiles_ms(seconds: list[NDArray[np.float64]]) -> dict[str, float]:
    """p50, p99 and max (ms) of per-frame seconds, each the median over the runs."""
    return {name: float(np.median([np.percentile(s, q) for s in seconds])) * 1e3
            for name, q in (("p50", 50), ("p99", 99), ("max", 100))}


def _chain_result(terrain: str, name: str, times: tuple[list[float], list[float]],
                  runs: list[MapRun], cpu: int | None) -> Result:
    log, walls = runs[-1].log, times[0]
    mission = mission_seconds(log.stamps)
    wall = float(np.median(walls))
    detail: JSONDict = {
        "rtf": mission / wall, "wall_s": walls, "cpu_s": times[1], "pinned_cpu": cpu,
        "mission_s": mission,
        "frames": len(log.stamps), "points_per_frame": float(np.mean(log.points)),
        "latency_ms": _quantiles_ms([r.log.latency_s for r in runs]),
        "insert_ms": _quantiles_ms([r.log.insert_s for r in runs]),
        "sensor_period_ms": ROTATION_S * 1e3, "domain_policy": runs[-1].info.domain_policy,
        "params": runs[-1].info.params.as_dict(), "feed": runs[-1].info.feed.value}
    return Result(10, f"alte map BAG, {name}, {terrain}", wall, mission, "s",
                  f"wall <= {LIMITS[10]:g} x mission (>= {1 / LIMITS[10]:g}x real time)",
                  bool(wall <= LIMITS[10] * mission), detail)


def streaming_chain(ctx: Context) -> list[Result]:
    """Row 10: real-time factor and per-frame latency of ``alte map BAG`` per mapper (every
    registered one, plugins included), each on both terrains."""
    from alte.lab.studies.thesis.numbers import mapper_params
    from alte.mappers import Feed, registry
    from alte.pipeline import DomainPolicy, MapSettings

    cfg = ctx.config
    out: list[Result] = []
    for terrain in (NAV, LAN):
        bag = _bag(ctx, terrain)
        params = mapper_params(terrain)
        specs = {cls.name: MapSettings(cls, dict(params.get(cls.name, {})), DomainPolicy.AUTO,
                                   Feed.FRAMES) for cls in registry.classes()}
        times: dict[str, tuple[list[float], list[float]]] = {name: ([], []) for name in specs}
        runs: dict[str, list[MapRun]] = {name: [] for name in specs}
        rounds = list(interleave(list(specs), cfg.warmup + cfg.repeats))
        with one_core() as cpu:
            for r, name in tqdm(rounds, desc=f"alte map {terrain}", unit="run",
                                disable=not cfg.progress, leave=False):
                wall, used, result = _one_run(bag, specs[name])
                if r >= cfg.warmup:
                    times[name][0].append(wall)
                    times[name][1].append(used)
                    runs[name].append(result)
        out.extend(_chain_result(terrain, name, times[name], runs[name], cpu) for name in specs)
    return out


class UfoPeer:
    """DUFOMap's scan integration behind the ``insert(points, origin)`` of a mapper."""

    def __init__(self, voxel: float, threads: int) -> None:
        os.environ.setdefault("GLOG_minloglevel", "2")  # its per-map INFO lines
        import dufomap

        self._map = dufomap.dufomap(voxel, 0.0, 0, num_threads=threads, hit_extension=False,
                                    ray_passthrough_hits=False)

    def insert(self, points: Points, origin: Points) -> None:
        """Cast the scan's rays from ``origin`` (points already in the map frame)."""
        pose = np.eye(4)
        pose[:3, 3] = origin
        self._map.run(np.asarray(points), pose, cloud_transform=False)


def scan_peer(ctx: Context) -> list[Result]:
    """Row 11: native Octomap vs DUFOMap (UFOMap) integrating the same scans at 0.2 m."""
    from alte.mappers import Octomap
    from bench.maps import Inserts, mapper_setup

    setup = mapper_setup(ctx, Octomap)
    voxel = 1.0 / float(setup.params.get("resolution", 5.0))
    threads = 1  # the native Octomap walks a scan's rays on one thread
    makers: dict[str, Callable[[], Inserts]] = {
        "native": setup.make,
        "dufomap": lambda: UfoPeer(voxel, threads)}
    scans: Sequence[Scan] = ctx.scans(NAV)
    cfg = ctx.config
    passes = interleaved_passes(makers, scans, repeats=cfg.repeats, warmup=cfg.warmup,
                                progress=cfg.progress, desc="dufomap")
    ours, peer = np.median(passes.totals("native")), np.median(passes.totals("dufomap"))
    p99 = {k: float(np.median([np.percentile(t, 99) for t in v])) * 1e3
           for k, v in passes.latencies.items()}
    detail: JSONDict = {
        "frames": len(scans), "voxel_m": voxel, "threads": threads,
        "native_s": passes.totals("native"), "dufomap_s": passes.totals("dufomap"),
        "p99_ms": p99, "dufomap_options": {"d_s": 0.0, "d_p": 0, "hit_extension": False,
                                           "ray_passthrough_hits": False}}
    return [Result(11, f"Octomap native vs DUFOMap scan integration, {NAV} ({len(scans)} frames)",
                   float(ours), float(peer), "s", f"ratio <= {LIMITS[11]:g}",
                   bool(ours <= LIMITS[11] * peer), detail)]
