"""Row 13: the sweep's throughput in runs per core-second, and a grid's time from it.

A sweep spends its time in its per-run work (:mod:`alte.lab.studies.sweep.groups`): feeding a
map once for the runs that share it, measuring it per run. The row draws a stratified
sample of a spec's map groups: one group per stratum (mapper, the value of its size
parameter, domain), each stratum having one group per terrain and seed, on a terrain
drawn at random (seed 0). Each group runs as the sweep runs it (``run_group``), its
inputs prepared beforehand (registration loaded, the reference's grids and truth: once
per worker and input in a sweep, timed apart). Figures are process CPU seconds (every
thread), which other load on a shared machine does not inflate.

Cases: 20-scan missions (``notebooks/sweeps/tradeoff.yaml``) and whole missions
(``tradeoff-full.yaml``). The peer is today's path before the grouping, one fresh map
per run measured from scratch (``experiments.measure``), on one run per sampled group.
The grid's estimate: each stratum's sampled CPU times its groups in the grid, plus each
input's preparation once per worker and its simulation and registration; its wall time
on ``WORKERS`` workers is that CPU over ``WORKERS``. Quick mode runs both specs on a few
scans of two terrains, a dozen strata each.
"""

from __future__ import annotations

import random
import time
from collections import Counter
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING, TypeVar

from tqdm.auto import tqdm

from alte.types import JSONDict
from bench.core import Context, Result
from bench.workload import QUICK_FRAMES, workload_dir

if TYPE_CHECKING:
    from alte.lab.studies.sweep import SweepSpec
    from alte.lab.studies.sweep.groups import MapGroup
    from alte.lab.studies.sweep.runs import SweepRun

__all__ = ["GRID_HOURS", "WORKERS", "Sample", "grid_estimate", "size_param", "stratified_groups",
           "sweep_throughput"]
#: Workers the grid's wall time is estimated for (this machine's cores).
WORKERS = 2
#: The whole-mission grid's target wall time on WORKERS cores (hours).
GRID_HOURS = 2.0
#: Target: seconds of one core per run (whole missions).
RUN_CORE_S = 0.3
#: Strata sampled in quick mode (evenly spaced among the spec's).
QUICK_STRATA = 12
_T = TypeVar("_T")
_SPECS = (("20 scans", "notebooks/sweeps/tradeoff.yaml"),
          ("whole missions", "notebooks/sweeps/tradeoff-full.yaml"))


@dataclass(frozen=True)
class Sample:
    """A measured stratified sample of a spec's map groups and what it says of the grid."""

    runs: int
    groups: int
    cpu_s: float
    prepare_s: float
    grid_runs: int
    grid_cpu_s: float
    per_stratum: list[JSONDict]

    @property
    def runs_per_core_s(self) -> float:
        """Runs per second of one core, over the sample."""
        return self.runs / self.cpu_s if self.cpu_s else float("nan")


def size_param(run: SweepRun) -> str | None:
    """The parameter that sets the run's map size (its stratum in the sample): the first
    of its mapper's ``settings_grid`` (None: a mapper without one)."""
    return next(iter(run.cls.settings_grid), None)


def _size(run: SweepRun) -> float:
    """The run's size parameter (a number, as the spec's rows were coerced)."""
    name = size_param(run)
    value = run.params.get(name, 0) if name is not None else 0
    return value if isinstance(value, int | float) else float("nan")


def _stratum(run: SweepRun) -> tuple[str, float, str]:
    return run.mapper, _size(run), run.domain


def stratified_groups(spec: SweepSpec, seed: int = 0) -> list[tuple[MapGroup, int]]:
    """One map group per stratum of ``spec`` (its first seed, terrain drawn with
    ``seed``) and the stratum's number of runs in the whole grid (every seed)."""
    from alte.lab.studies.sweep import override, plan_runs
    from alte.lab.studies.sweep.groups import group_runs

    everything: Counter[tuple[str, float, str]] = Counter()
    for g in group_runs(plan_runs(spec)):
        everything[_stratum(g.runs[0])] += len(g)
    first = group_runs(plan_runs(override(spec, seeds=[spec.seeds[0]])))
    by: dict[tuple[str, float, str], list[MapGroup]] = {}
    for group in first:
        by.setdefault(_stratum(group.runs[0]), []).append(group)
    rng = random.Random(seed)
    return [(rng.choice(by[key]), everything[key]) for key in sorted(by, key=str)]


def _thinned(items: list[_T], most: int | None) -> list[_T]:
    if most is None or len(items) <= most:
        return items
    step = len(items) / most
    return [items[int(i * step)] for i in range(most)]


def _prepare_input(run: SweepRun, data_dir: str) -> float:
    """CPU seconds to simulate/register (if needed) and prepare one run's input."""
    from alte.lab.studies.sweep.groups import _inputs
    from alte.lab.studies.sweep.runner import _ensure

    start = time.process_time()
    _ensure(run, data_dir)
    _, reference = _inputs(run, data_dir)
    reference.cloud_index  # noqa: B018 - prepared now, as a worker does on its first map
    if reference.truth is not None:
        for part in ("samples", "seen", "sample_tree", "probes"):
            getattr(reference, part)
    return time.process_time() - start


def measure_sample(spec: SweepSpec, data_dir: str, *, seed: int = 0, strata: int | None = None,
                   progress: bool = False) -> Sample:
    """Run :func:`stratified_groups` of ``spec`` (``strata``: at most that many, evenly
    spaced) as a sweep does; see :class:`Sample`."""
    from alte.lab.studies.sweep.groups import run_group

    every = stratified_groups(spec, seed)
    chosen = _thinned(every, strata)
    prepared: dict[tuple[object, ...], float] = {}
    rows: list[JSONDict] = []
    runs, cpu, estimate, sampled_in_grid = 0, 0.0, 0.0, 0
    for group, in_grid in tqdm(chosen, desc="sweep sample", unit="map", disable=not progress):
        first = group.runs[0]
        key = first.input_key()
        if key not in prepared:
            prepared[key] = _prepare_input(first, data_dir)
        start = time.process_time()
        outcomes = run_group(group, data_dir)
        used = time.process_time() - start
        failed = [err for _, _, err in outcomes if err is not None]
        if failed:
            raise failed[0]
        # the stratum's runs in the grid cost what these cost per run
        runs, cpu, estimate = runs + len(group), cpu + used, estimate + used / len(group) * in_grid
        sampled_in_grid += in_grid
        rows.append({"mapper": first.mapper, "size": _size(first),
                     "domain": first.domain, "terrain": first.terrain, "runs": len(group),
                     "cpu_s": round(used, 3), "runs_in_grid": in_grid})
    grid_runs = sum(n for _, n in every)  # strata left out cost what the sampled ones do
    return Sample(runs, len(chosen), cpu, sum(prepared.values()) / len(prepared), grid_runs,
                  estimate * grid_runs / sampled_in_grid, rows)


def grid_estimate(sample: Sample, inputs: int, workers: int = WORKERS) -> dict[str, float]:
    """The grid's CPU hours (its maps and measures, plus preparing each of ``inputs``
    once per worker) and its wall hours on ``workers`` cores."""
    cpu = sample.grid_cpu_s + sample.prepare_s * inputs * workers
    return {"cpu_h": cpu / 3600, "wall_h": cpu / workers / 3600,
            "runs_per_core_s": sample.grid_runs / cpu if cpu else float("nan")}


def _peer(sample_spec: SweepSpec, data_dir: str, seed: int, strata: int | None
          ) -> tuple[int, float]:
    """Runs and CPU seconds of today's path (one fresh map per run, metrics from scratch)
    on the first run of each sampled group."""
    from alte.lab.studies.experiments import measure
    from alte.lab.studies.sweep.groups import _inputs
    from alte.pipeline import DomainPolicy, MapSettings

    runs, cpu = 0, 0.0
    for group, _ in _thinned(stratified_groups(sample_spec, seed), strata):
        run = group.runs[0]
        data, _ = _inputs(run, data_dir)
        start = time.process_time()
        measure(data, run.mapper, truth=run.truth, set_b=run.set_b,
                spec=MapSettings(run.mapper, dict(run.params), domain=DomainPolicy(run.domain)))
        runs, cpu = runs + 1, cpu + time.process_time() - start
    return runs, cpu


def _spec(path: str, ctx: Context, data_dir: str) -> SweepSpec:
    from alte.lab.studies.sweep import load_spec, override

    spec = override(load_spec(path), data_dir=data_dir)
    if not ctx.config.quick:
        return spec
    terrains = ("sim_lan_2", "sim_nav_1")
    mappers = tuple(replace(g, terrains=tuple(t for t in g.terrains if t in terrains))
                    for g in spec.mappers)
    # quick mode leaves out odometry variants: they pose whole missions
    variants = tuple(replace(v, terrains=tuple(t for t in v.terrains if t in terrains))
                     for v in spec.variants if v.poses == "recorded")
    return override(replace(spec, terrains=terrains, mappers=mappers, variants=variants),
                    frames=QUICK_FRAMES)


def sweep_throughput(ctx: Context) -> list[Result]:
    """Row 13 (module docstring): one result per case."""
    cfg = ctx.config
    data_dir = str(workload_dir(cfg.data_dir, cfg.quick).resolve())
    out = []
    strata = QUICK_STRATA if cfg.quick else None
    for case, path in _SPECS:
        spec = _spec(path, ctx, data_dir)
        sample = measure_sample(spec, data_dir, strata=strata, progress=cfg.progress)
        inputs = len({(t, s) for t in spec.terrains for s in spec.seeds})
        grid = grid_estimate(sample, inputs)
        peer_runs, peer_cpu = _peer(spec, data_dir, 0, strata)
        peer = peer_runs / peer_cpu if peer_cpu else float("nan")
        whole = case == "whole missions" and not cfg.quick
        met = (grid["wall_h"] <= GRID_HOURS) if whole else None
        target = (f"full grid <= {GRID_HOURS:g} h on {WORKERS} cores (~{RUN_CORE_S} core-s "
                  "a run)" if whole else "informative")
        out.append(Result(13, f"sweep runs per core-second, {case} ({Path(path).name}, "
                              f"{sample.runs} runs in {sample.groups} maps)",
                          sample.runs_per_core_s, peer, "runs/core-s", target, met, {
                              "sample_runs": sample.runs, "sample_cpu_s": sample.cpu_s,
                              "prepare_cpu_s_per_input": sample.prepare_s,
                              "grid_runs": sample.grid_runs, "grid_inputs": inputs,
                              "grid_cpu_h": grid["cpu_h"], "grid_wall_h": grid["wall_h"],
                              "grid_runs_per_core_s": grid["runs_per_core_s"],
                              "workers": WORKERS, "peer_runs": peer_runs,
                              "peer_cpu_s": peer_cpu, "per_stratum": sample.per_stratum}))
    return out
