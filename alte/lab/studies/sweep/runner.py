"""Run a sweep serially or on Dask distributed, appending rows to a Parquet dataset.

Data flows one way: spec -> runs (minus those already stored) -> terrains ensured
(one task per distinct terrain and seed: it simulates the folder if needed and
registers it once into the cache ``DATA_DIR/.cache``, so no two workers simulate or
register the same data) -> one task per map the runs share on the workers
(:func:`~alte.lab.studies.sweep.groups.run_group`: load the cached registration, feed the map
once, measure it for each of its runs, return their flat rows), ordered by seed and
terrain so that each worker prepares an input once -> the client writes each finished
row to its own Parquet file, with a progress bar over runs and its ETA. The client is
the only writer; workers only read terrain folders and the registration cache.
"""

from __future__ import annotations

import contextlib
import dataclasses
import logging
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Protocol, TypeVar

import pandas as pd
import pyarrow as pa

from alte.errors import ParameterError, SimulationError
from alte.lab.studies.sweep.groups import MapGroup, group_runs, input_data, run_group, run_one
from alte.lab.studies.sweep.runs import SweepRun, plan_runs, plan_variants
from alte.lab.studies.sweep.spec import SweepSettings, SweepSpec, with_plugins
from alte.lab.studies.sweep.store import finished_ids, load_results, row_table, write_row
from alte.progress import bar as progress_bar

__all__ = ["CLUSTER_OPTIONS", "SERIAL", "MapUnordered", "SweepResult", "executor",
           "input_order", "override", "run_one", "run_sweep", "variant_table"]

#: How long to wait for a scheduler given by address.
CONNECT_TIMEOUT = "10s"
#: A local cluster's worker that has not answered its scheduler for this long is restarted
#: and its tasks run again (Dask's default: 5 minutes). A worker's event loop answers
#: while its task runs; it stops only when the process hangs. That happened once in a
#: report's grid: 2 runs of a few seconds each waited 5 minutes, both workers' share of
#: the grid otherwise done, and took 4 s on the restarted worker. No task of a sweep or
#: of the sensor study holds the interpreter for a minute.
WORKER_TTL = "90s"
#: ``scheduler`` values that run everything in this process.
SERIAL = frozenset({"serial", "none"})
#: A local cluster's options: single-threaded worker processes (numba one thread each:
#: the workers are the parallelism); no dashboard, and the scheduler's HTTP server (health
#: routes) on a free port: on distributed's 8787 a second cluster at once (two sweeps, two
#: test workers) warned that the port was taken.
CLUSTER_OPTIONS: dict[str, object] = {
    "threads_per_worker": 1, "processes": True, "dashboard_address": None,
    "scheduler_kwargs": {"dashboard_address": ":0"}, "env": {"NUMBA_NUM_THREADS": "1"}}

if TYPE_CHECKING:
    from distributed import Client

_Item = TypeVar("_Item")
_Result = TypeVar("_Result")

#: Outcome of one task: (index into the submitted items, result or None, error or None).
Outcome = tuple[int, _Result | None, BaseException | None]


class MapUnordered(Protocol):
    """Call ``fn(item, data_dir)`` for each item; yield each :data:`Outcome` as it ends."""

    def __call__(self, fn: Callable[[_Item, str], _Result], items: Sequence[_Item],
                 data_dir: str, /) -> Iterator[Outcome[_Result]]: ...


@dataclass(frozen=True)
class SweepResult:
    """What :func:`run_sweep` did: the spec's rows (grid order) and the run tallies."""

    output: Path
    table: pd.DataFrame
    ran: int
    skipped: int
    failed: list[tuple[SweepRun, str]] = field(default_factory=list)

    def summary(self) -> dict[str, object]:
        """Counts and failures, JSON-ready (for ``save_results``)."""
        return {"output": str(self.output), "rows": len(self.table), "ran": self.ran,
                "skipped": self.skipped,
                "failed": [{"run_id": r.run_id, "terrain": r.terrain, "mapper": r.mapper,
                            "params": dict(r.params), "error": msg} for r, msg in self.failed]}


def _ensure(run: SweepRun, data_dir: str) -> str:
    """Simulate the run's terrain if needed and register it into the cache (once per
    :meth:`~SweepRun.input_key`)."""
    return str(input_data(run, data_dir).source.path)


def _serial_map(fn: Callable[[_Item, str], _Result], items: Sequence[_Item],
                data_dir: str, /) -> Iterator[Outcome[_Result]]:
    for i, item in enumerate(items):
        try:
            yield i, fn(item, data_dir), None
        except Exception as err:  # a failed run is reported, the sweep goes on
            yield i, None, err


def _dask_map(client: Client) -> MapUnordered:
    from distributed import as_completed

    def map_unordered(fn: Callable[[_Item, str], _Result], items: Sequence[_Item],
                      data_dir: str, /) -> Iterator[Outcome[_Result]]:
        futures = [client.submit(fn, item, data_dir, pure=False) for item in items]
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
def _local_cluster(workers: int) -> Iterator[Client]:
    """A client of a LocalCluster of ``workers`` single-threaded processes (numba's kernels
    too: the workers are the parallelism), whose scheduler restarts a worker silent for
    :data:`WORKER_TTL`. Once the work is done its nannies' warnings are no news: closing,
    a nanny gives its worker 4 s to exit, then kills it and says so ("Worker process
    still alive after 4.0 seconds, killing"), on every report run, the results all in;
    warnings while the cluster works (a worker restarted) still show."""
    import dask
    from distributed import Client, LocalCluster

    nanny = logging.getLogger("distributed.nanny")
    level = nanny.level
    try:
        with dask.config.set({"distributed.scheduler.worker-ttl": WORKER_TTL}), \
                LocalCluster(n_workers=workers, **CLUSTER_OPTIONS) as cluster:
            try:
                with Client(cluster) as client:
                    yield client
            finally:
                nanny.setLevel(logging.ERROR)
    finally:
        nanny.setLevel(level)


@contextlib.contextmanager
def executor(scheduler: str, workers: int) -> Iterator[MapUnordered]:
    """A :class:`MapUnordered` on ``scheduler``: ``serial``/``none`` in-process; ``local`` a
    LocalCluster of ``workers`` single-threaded processes; else a scheduler address."""
    if scheduler in SERIAL:
        yield _serial_map
        return
    from distributed import Client

    if scheduler == "local":
        if workers < 1:
            raise ParameterError(f"sweep: workers={workers} out of range (workers >= 1)",
                                 setting="sweep.workers")
        with _local_cluster(workers) as client:
            yield _dask_map(client)
        return
    if "://" not in scheduler:
        raise ParameterError(f"sweep: scheduler={scheduler!r}: expected serial, none, local "
                             "or an address like tcp://host:8786", setting="sweep.scheduler")
    try:
        client = Client(scheduler, timeout=CONNECT_TIMEOUT)
    except (OSError, TimeoutError) as err:
        raise ParameterError(f"sweep: scheduler={scheduler}: cannot connect ({err})",
                             setting="sweep.scheduler") from err
    with client:
        yield _dask_map(client)


def input_order(key: tuple[object, ...]) -> tuple[bool, str]:
    """Inputs posed by odometry first (a whole mission simulated and aligned: the longest
    tasks, ~45 CPU s of LIO each), so that no worker starts one while the other has
    nothing left to do; the rest by key."""
    return key[-1] != "odometry", str(key)


def _ensure_all(pool: MapUnordered, runs: Sequence[SweepRun], data_dir: str,
                progress: bool) -> None:
    inputs = {r.input_key(): r for r in runs}
    items = [inputs[key] for key in sorted(inputs, key=input_order)]
    bar = progress_bar(total=len(items), desc="sweep terrains", unit="terrain",
                       disable=not progress)
    with bar:
        for i, _, err in pool(_ensure, items, data_dir):
            if err is not None:
                raise SimulationError(f"sweep: terrain {items[i].terrain} (frames="
                                      f"{items[i].frames}) could not be simulated: {err}"
                                      ) from err
            bar.update()


def _by_input(runs: Sequence[SweepRun]) -> list[MapGroup]:
    """The runs' map groups, those of one seed and terrain side by side (in spec order)."""
    order = {key: i for i, key in enumerate(dict.fromkeys((r.seed, r.terrain) for r in runs))}
    return sorted(group_runs(runs), key=lambda g: order[(g.runs[0].seed, g.runs[0].terrain)])


def _map_all(pool: MapUnordered, runs: Sequence[SweepRun], data_dir: str, out: Path,
             progress: bool) -> tuple[list[tuple[SweepRun, str]], dict[str, pa.Table]]:
    """Map every run; (the failed runs with their errors, run id -> the table written)."""
    failed, written = [], {}
    groups = _by_input(runs)
    by_id = {r.run_id: r for r in runs}
    # smoothing 0: the ETA from the mean rate so far (maps of one input differ widely)
    with progress_bar(total=len(runs), desc="sweep runs", unit="run", disable=not progress,
              smoothing=0) as bar:
        for i, done, err in pool(run_group, groups, data_dir):
            # err: the task itself failed (e.g. a lost worker), so did each of its runs
            outcomes = (done if err is None and done is not None
                        else [(r.run_id, None, err) for r in groups[i].runs])
            for run_id, row, error in outcomes:
                if error is None and row is not None:
                    written[run_id] = row_table(row)
                    write_row(out, written[run_id])
                else:
                    failed.append((by_id[run_id], f"{type(error).__name__}: {error}"))
            bar.update(len(outcomes))
    return failed, written


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
    written: dict[str, pa.Table] = {}
    if todo:
        with executor(scheduler, workers) as pool:
            _ensure_all(pool, todo, data_dir, progress)
            failed, written = _map_all(pool, todo, data_dir, out, progress)
    table = load_results(out, [r.run_id for r in runs], known=written)
    return SweepResult(out, table, len(todo) - len(failed), len(runs) - len(todo), failed)


def override(spec: SweepSpec, **changes: object) -> SweepSpec:
    """``spec`` with other ``frames``/``data_dir``/``output``/``seed``/``seeds`` (CLI and
    notebook), checked as :class:`SweepSettings`; ``None`` keeps the spec's value, except
    for ``frames`` (the whole mission). ``plugins=True`` adds the installed plugin mappers
    (:func:`~alte.lab.studies.sweep.spec.with_plugins`)."""
    allowed = ("frames", "data_dir", "output", "seed", "seeds", "plugins")
    unknown = sorted(set(changes) - set(allowed))
    if unknown:
        raise ParameterError(f"sweep override {', '.join(unknown)}: valid: {', '.join(allowed)}")
    if changes.pop("plugins", None):
        spec = with_plugins(dataclasses.replace(
            spec, settings=spec.settings.replace(plugins=True)))
    given = {k: v for k, v in changes.items() if k == "frames" or v is not None}
    new = SweepSettings.parse(given)  # checked alone first: errors name only what was given
    kept = {**spec.settings.as_dict(), "output": spec.output}
    if {"seed", "seeds"} & set(given):
        kept |= {"seed": new.seed, "seeds": new.seeds}
    changed: dict[str, object] = {k: getattr(new, k) for k in ("frames", "data_dir", "output")
                                  if k in given}
    if not changed.get("output", True):
        del changed["output"]
    return dataclasses.replace(spec, settings=SweepSettings.parse({**kept, **changed}))


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
