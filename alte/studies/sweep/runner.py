"""Run a sweep serially or on Dask distributed, appending rows to a Parquet dataset.

Data flows one way: spec -> runs (minus those already stored) -> terrains ensured
(one task per distinct terrain and seed: it simulates the folder if needed and
registers it once into the cache ``DATA_DIR/.cache``, so no two workers simulate or
register the same data) -> one task per run on the workers (:func:`run_one`: load the
cached registration, map, measure, return a flat row) -> the client writes each
finished row to its own Parquet file. The client is the only writer; workers only
read terrain folders and the registration cache.
"""

from __future__ import annotations

import contextlib
import dataclasses
import functools
import json
import time
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pandas as pd
from tqdm.auto import tqdm

from alte.errors import ParameterError, SimulationError
from alte.mappers import mapper_class
from alte.pipeline import DomainPolicy, FrameSpec, MapSpec, Registered, open_input, prepare
from alte.sim import ensure_terrain, terrain_folder
from alte.sim.profile import PROFILES
from alte.studies.experiments import CACHE_DIR, measure
from alte.studies.obstacles import obstacle_columns, obstacle_options
from alte.studies.sweep.spec import SweepRun, SweepSettings, SweepSpec, plan_runs, plan_variants
from alte.studies.sweep.store import finished_ids, load_results, write_row

__all__ = ["SERIAL", "SweepResult", "override", "run_one", "run_sweep", "variant_table"]

#: How long to wait for a scheduler given by address.
CONNECT_TIMEOUT = "10s"
#: ``scheduler`` values that run everything in this process.
SERIAL = frozenset({"serial", "none"})

#: Outcome of one task: (index into the submitted items, result, error or None).
Outcome = tuple[int, Any, BaseException | None]
MapUnordered = Callable[..., Iterator[Outcome]]


@dataclass(frozen=True)
class SweepResult:
    """What :func:`run_sweep` did: the spec's rows (grid order) and the run tallies."""

    output: Path
    table: pd.DataFrame
    ran: int
    skipped: int
    failed: list[tuple[SweepRun, str]] = field(default_factory=list)

    def summary(self) -> dict[str, Any]:
        """Counts and failures, JSON-ready (for ``save_results``)."""
        return {"output": str(self.output), "rows": len(self.table), "ran": self.ran,
                "skipped": self.skipped,
                "failed": [{"run_id": r.run_id, "terrain": r.terrain, "mapper": r.mapper,
                            "params": dict(r.params), "error": msg} for r, msg in self.failed]}


@functools.lru_cache(maxsize=2)
def _dataset(folder: str, frames: int | None, voxel: float | None, data_dir: str,
             deskew: bool = True) -> Registered:
    """Per-process memo over the on-disk registration cache (``DATA_DIR/.cache``)."""
    return prepare(open_input(folder), FrameSpec(frames=frames, voxel=voxel, deskew=deskew),
                   cache=Path(data_dir) / CACHE_DIR)


def run_one(run: SweepRun, data_dir: str) -> dict[str, Any]:
    """Map one run's terrain and return its flat row (keys, ``p_*`` params, metrics, the
    map's time and machine-independent ``cost`` with its ``cost_unit``, and the whole
    run's cost: ``wall_s`` and ``cpu_s``, the CPU seconds of every thread of the process,
    which other load on the machine does not inflate)."""
    start, cpu = time.perf_counter(), time.process_time()
    folder = terrain_folder(data_dir, run.terrain, run.frames, run.seed, PROFILES[run.sensor])
    data = _dataset(str(folder), run.frames, run.voxel, data_dir, run.deskew)
    spec = MapSpec(run.mapper, dict(run.params), domain=DomainPolicy(run.domain))
    found = measure(data, run.mapper, truth=run.truth, spec=spec, set_b=run.set_b,
                    obstacles=obstacle_options(run.terrain) if run.obstacles else None)
    metrics = found.metrics.flat()
    return {
        "run_id": run.run_id, "terrain": run.terrain, "frames_requested": run.frames or 0,
        "seed": run.seed, "mapper": run.mapper,
        "params_json": json.dumps(dict(run.params), sort_keys=True),
        **{f"p_{k}": v for k, v in run.params.items()},
        "domain": run.domain, "set_b": run.set_b, "sensor": run.sensor, "deskew": run.deskew,
        "frames": len(data), "points": len(data.cloud),
        **{k: v for k, v in metrics.items() if k != "elapsed_s"},
        **obstacle_columns(found.obstacles),
        "cost_unit": mapper_class(run.mapper).cost_unit.value,
        "elapsed_s": float(metrics["elapsed_s"]), "wall_s": time.perf_counter() - start,
        "cpu_s": time.process_time() - cpu,
    }


def _ensure(item: tuple[str, int | None, int, float | None, str, bool], data_dir: str) -> str:
    """Simulate the terrain if needed and register it into the cache (once per item)."""
    terrain, frames, seed, voxel, sensor, deskew = item
    folder = ensure_terrain(terrain, data_dir, seed, frames, profile=PROFILES[sensor])
    prepare(open_input(folder), FrameSpec(frames=frames, voxel=voxel, deskew=deskew),
            cache=Path(data_dir) / CACHE_DIR)
    return str(folder)


def _serial_map(fn: Callable[..., Any], items: Sequence[Any], *args: Any) -> Iterator[Outcome]:
    for i, item in enumerate(items):
        try:
            yield i, fn(item, *args), None
        except Exception as err:  # a failed run is reported, the sweep goes on
            yield i, None, err


def _dask_map(client: Any) -> MapUnordered:
    from distributed import as_completed

    def map_unordered(fn: Callable[..., Any], items: Sequence[Any],
                      *args: Any) -> Iterator[Outcome]:
        futures = [client.submit(fn, item, *args, pure=False) for item in items]
        index = {f.key: i for i, f in enumerate(futures)}
        for future in as_completed(futures):
            try:
                yield index[future.key], future.result(), None
            except Exception as err:  # re-raised from the worker
                yield index[future.key], None, err
            finally:
                future.release()
    return map_unordered


@contextlib.contextmanager
def _executor(scheduler: str, workers: int) -> Iterator[MapUnordered]:
    """``serial``/``none``: in-process; ``local``: a LocalCluster; else a scheduler address."""
    if scheduler in SERIAL:
        yield _serial_map
        return
    from distributed import Client, LocalCluster

    if scheduler == "local":
        if workers < 1:
            raise ParameterError(f"--workers {workers}: must be at least 1")
        # One thread per worker, numba's kernels included: the workers are the parallelism.
        with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                          dashboard_address=None, env={"NUMBA_NUM_THREADS": "1"},
                          ) as cluster, Client(cluster) as client:
            yield _dask_map(client)
        return
    if "://" not in scheduler:
        raise ParameterError(f"--scheduler {scheduler!r}: expected serial, none, local or an "
                             "address like tcp://host:8786")
    try:
        client = Client(scheduler, timeout=CONNECT_TIMEOUT)
    except (OSError, TimeoutError) as err:
        raise ParameterError(f"--scheduler {scheduler}: cannot connect ({err})") from err
    with client:
        yield _dask_map(client)


def _ensure_all(pool: MapUnordered, runs: Sequence[SweepRun], data_dir: str,
                progress: bool) -> None:
    items = sorted({(r.terrain, r.frames, r.seed, r.voxel, r.sensor, r.deskew) for r in runs},
                   key=str)
    bar = tqdm(total=len(items), desc="terrains", unit="terrain", disable=not progress)
    with bar:
        for i, _, err in pool(_ensure, items, data_dir):
            if err is not None:
                raise SimulationError(f"sweep: terrain {items[i][0]} (frames={items[i][1]}) "
                                      f"could not be simulated: {err}") from err
            bar.update()


def _map_all(pool: MapUnordered, runs: Sequence[SweepRun], data_dir: str, out: Path,
             progress: bool) -> list[tuple[SweepRun, str]]:
    failed = []
    with tqdm(total=len(runs), desc="runs", unit="run", disable=not progress) as bar:
        for i, row, err in pool(run_one, runs, data_dir):
            if err is None:
                write_row(out, row)
            else:
                failed.append((runs[i], f"{type(err).__name__}: {err}"))
            bar.update()
    return failed


def run_sweep(spec: SweepSpec, *, scheduler: str = "local", workers: int = 2,
              output: str | Path | None = None, progress: bool = True) -> SweepResult:
    """Run the spec's unfinished runs and return all its rows in grid order.

    ``scheduler``: ``"serial"``/``"none"`` (in-process), ``"local"`` (a
    ``LocalCluster`` of ``workers`` single-threaded processes) or the address of a
    running scheduler (its workers must see the same ``data_dir`` and Python env).
    ``output`` overrides ``spec.output``. Failed runs are listed, not written, so a
    rerun retries them.
    """
    out = Path(output or spec.output).resolve()
    data_dir = str(Path(spec.data_dir).resolve())
    runs = plan_runs(spec)
    done = finished_ids(out)
    todo = [r for r in runs if r.run_id not in done]
    failed: list[tuple[SweepRun, str]] = []
    if todo:
        with _executor(scheduler, workers) as pool:
            _ensure_all(pool, todo, data_dir, progress)
            failed = _map_all(pool, todo, data_dir, out, progress)
    table = load_results(out, [r.run_id for r in runs])
    return SweepResult(out, table, len(todo) - len(failed), len(runs) - len(todo), failed)


def override(spec: SweepSpec, **changes: object) -> SweepSpec:
    """``spec`` with other ``frames``/``data_dir``/``output``/``seed``/``seeds`` (CLI and
    notebook), checked as :class:`SweepSettings`; ``None`` keeps the spec's value, except
    for ``frames`` (the whole mission)."""
    allowed = ("frames", "data_dir", "output", "seed", "seeds")
    unknown = sorted(set(changes) - set(allowed))
    if unknown:
        raise ParameterError(f"sweep override {', '.join(unknown)}: valid: {', '.join(allowed)}")
    given = {k: v for k, v in changes.items() if k == "frames" or v is not None}
    new = SweepSettings.parse(given)
    return dataclasses.replace(
        spec,
        frames=new.frames if "frames" in given else spec.frames,
        data_dir=new.data_dir if "data_dir" in given else spec.data_dir,
        output=new.output or spec.output,
        seeds=new.seed_list() if {"seed", "seeds"} & set(given) else spec.seeds)


def variant_table(spec: SweepSpec, table: pd.DataFrame) -> pd.DataFrame:
    """The rows of every variant of ``spec`` (base first) with a ``variant`` column: a run
    several variants share appears once per variant. ``table``: :func:`run_sweep`'s."""
    if table.empty:
        return table.assign(variant=pd.Series(dtype=str))
    rows = table.set_index("run_id", drop=False)
    pairs = [(name, run.run_id) for name, run in plan_variants(spec) if run.run_id in rows.index]
    out = rows.loc[[run_id for _, run_id in pairs]].reset_index(drop=True)
    out.insert(1, "variant", [name for name, _ in pairs])
    return out
