"""Execute a report: simulate missing terrains, run every notebook with papermill,
convert to HTML, write the run's index and record, then publish it as ``latest``.

A failing notebook never stops the others: its partial executed notebook is kept
as ``<name>.failed.ipynb`` and the failure is recorded. Each notebook executes
under a temporary name (``.<name>.part.ipynb``) that is renamed only when papermill
returns, so a killed report leaves nothing that looks finished.
"""

from __future__ import annotations

import contextlib
import os
import sys
import time
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import ThreadPoolExecutor, as_completed
from dataclasses import asdict, dataclass, field
from datetime import UTC, datetime
from pathlib import Path
from typing import TYPE_CHECKING, NoReturn, Protocol

from tqdm.auto import tqdm

from alte.errors import AlteError, ReportError
from alte.lab.report.html import notebook_to_html, run_index_html, top_index_html, write_html
from alte.lab.report.plan import Run
from alte.lab.report.runs import list_runs, new_run_dir, point_latest, publish_tables, write_record
from alte.lab.report.warm import Warmup
from alte.paths import REPO_ROOT
from alte.progress import Relay, Throttle
from alte.types import JSONDict

if TYPE_CHECKING:
    from traitlets.config import Config

__all__ = ["THREAD_VARIABLES", "Report", "RunResult", "cpu_seconds", "ensure_terrains",
           "execute_run", "kernel_threads", "run_report"]

class EnsureTerrain(Protocol):
    """``ensure(name, out_dir=..., seed=..., frames=...)`` makes a terrain's data exist
    (:func:`alte.sim.ensure_terrain`; frames None: the whole mission)."""

    def __call__(self, name: str, *, out_dir: Path, seed: int, frames: int | None) -> object:
        ...


@dataclass
class RunResult:
    """Outcome of one notebook run; paths are relative to the run folder."""

    name: str
    status: str
    seconds: float = 0.0
    notebook: str | None = None
    html: str | None = None
    error: str | None = None
    parameters: JSONDict = field(default_factory=dict)
    cpu_s: float | None = None


@dataclass
class Report:
    """Outcome of a whole report run."""

    run_dir: Path
    results: list[RunResult]
    problems: list[str]
    seconds: float
    tables: list[Path]

    @property
    def failed(self) -> list[RunResult]:
        """Runs that did not succeed (failed or skipped)."""
        return [r for r in self.results if r.status != "ok"]


def cpu_seconds(children: bool = True) -> float:
    """User + system CPU seconds of this process, or of its finished children (notebook
    kernels and the workers they waited for): a report's cost on a shared machine, where
    wall time counts the other users' load too."""
    import resource

    use = resource.getrusage(resource.RUSAGE_CHILDREN if children else resource.RUSAGE_SELF)
    return use.ru_utime + use.ru_stime


def _default_ensure() -> EnsureTerrain:
    try:
        from alte.sim import ensure_terrain
    except ImportError as err:
        raise ReportError(f"alte.sim.ensure_terrain is unavailable ({err})") from err
    return ensure_terrain


def _spec(runs: Sequence[Run], terrain: str, seed: int) -> tuple[int | None, int]:
    """Frames and seed to simulate ``terrain`` with, as the notebooks using it ask.

    Frames: the most any run asks for (None = the whole mission when any run wants
    all); seed: the runs' ``SEED`` when they agree on one, else ``seed``.
    """
    users = [r for r in runs if terrain in r.terrains]
    wanted = [r.value("FRAMES") for r in users]
    counts = [f for f in wanted if isinstance(f, int) and f > 0]
    full = not wanted or len(counts) < len(wanted)
    seeds = {s for s in (r.value("SEED") for r in users) if isinstance(s, int)}
    return (None if full else max(counts)), (seeds.pop() if len(seeds) == 1 else seed)


def ensure_terrains(runs: Sequence[Run], data_dir: Path, ensure: EnsureTerrain | None = None,
                    seed: int = 0, progress: bool = True) -> dict[str, str]:
    """Make every terrain the runs need exist in ``data_dir``; returns terrain -> error."""
    terrains = list(dict.fromkeys(t for r in runs for t in r.terrains))
    if not terrains:
        return {}
    ensure = ensure or _default_ensure()
    errors = {}
    for name in tqdm(terrains, desc="terrains", unit="terrain", disable=not progress):
        frames, terrain_seed = _spec(runs, name, seed)
        try:
            ensure(name, out_dir=data_dir, seed=terrain_seed, frames=frames)
        except AlteError as err:
            errors[name] = f"terrain {name}: {err}"
        except Exception as err:  # a simulator bug must not stop the other terrains
            errors[name] = f"terrain {name}: {type(err).__name__}: {err}"
    return errors


def _injected(run: Run, run_dir: Path, data_dir: Path) -> dict[str, str]:
    given = {"OUT_DIR": run_dir / run.name, "TABLES_DIR": run_dir / "tables",
             "DATA_DIR": data_dir}
    return {k: str(v) for k, v in given.items() if k in run.defaults}


def _kernel_config() -> Config:
    """Kernels encrypt their local TCP traffic (CurveZMQ, which the python3 kernelspec
    declares) when pyzmq can, instead of ipykernel warning about plain text per run."""
    import zmq
    from traitlets.config import Config

    return Config({"KernelManager": {"transport_encryption": "auto"}} if zmq.has("curve")
                  else {})


#: Thread pools a kernel's libraries size from these (OpenMP: pykdtree, Open3D; OpenBLAS
#: and MKL: numpy's linear algebra; numba's parallel kernels). Beside other kernels each
#: gets its share of the cores, as Dask gives its workers one thread: idle threads of a
#: pool spin while they wait, and with every core busy that was CPU taken from the other
#: notebooks (chapter 6's pose table: 140 CPU s with two OpenBLAS and OpenMP threads, 87
#: with one, on an otherwise idle 2-core machine, in 95 and 87 s). Variables the user set
#: are kept.
THREAD_VARIABLES = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS",
                    "NUMBA_NUM_THREADS")


@contextlib.contextmanager
def kernel_threads(jobs: int) -> Iterator[dict[str, str]]:
    """The :data:`THREAD_VARIABLES` the user left unset, set for the kernels started
    meanwhile to the cores over ``jobs`` (at least one); yields what was set."""
    share = str(max(1, (os.cpu_count() or 1) // max(1, jobs)))
    given = {name: share for name in THREAD_VARIABLES if name not in os.environ}
    os.environ.update(given)
    try:
        yield given
    finally:
        for name in given:
            os.environ.pop(name, None)


#: The kernel logs only what is critical: jupyter_client interrupts every kernel before it
#: shuts it down, and ipykernel then logs "KeyboardInterrupt caught in kernel", noise a
#: report's reader cannot act on (a cell's error is in the notebook, a dead kernel in the
#: run's status).
KERNEL_ARGUMENTS = ["--IPKernelApp.log_level=CRITICAL"]


def execute_run(run: Run, run_dir: Path, data_dir: Path, cwd: Path = REPO_ROOT,
                kernel_name: str = "python3") -> RunResult:
    """Execute one notebook into ``run_dir``; failures are returned, never raised."""
    import papermill

    params: JSONDict = {**run.parameters, **_injected(run, run_dir, data_dir)}
    tmp = run_dir / f".{run.name}.part.ipynb"
    start, cpu = time.perf_counter(), cpu_seconds()
    status, error = "ok", None
    try:
        papermill.execute_notebook(str(run.notebook), str(tmp), parameters=params,
                                   kernel_name=kernel_name, cwd=str(cwd), progress_bar=False,
                                   config=_kernel_config(), extra_arguments=KERNEL_ARGUMENTS)
    except papermill.PapermillExecutionError as err:
        status, error = "failed", f"cell {err.exec_count}: {err.ename}: {err.evalue}"
    except Exception as err:  # dead kernel, timeout, unreadable notebook: isolate it too
        status, error = "failed", f"{type(err).__name__}: {err}"
    result = RunResult(run.name, status, error=error, parameters=params)
    if tmp.exists():
        final = run_dir / (f"{run.name}.ipynb" if status == "ok" else f"{run.name}.failed.ipynb")
        os.replace(tmp, final)
        result.notebook = final.name
        try:
            result.html = notebook_to_html(final, final.with_suffix(".html")).name
        except ReportError as err:
            result.error = f"{error or ''}; {err}".lstrip("; ")
    result.seconds = time.perf_counter() - start
    result.cpu_s = cpu_seconds() - cpu  # its kernel's (exact when runs do not overlap)
    return result


def _execute_all(runs: Sequence[Run], run_dir: Path, data_dir: Path, skip: dict[str, str], *,
                 jobs: int, progress: bool, cwd: Path) -> list[RunResult]:
    done: dict[str, RunResult] = {}
    todo = []
    for run in runs:
        missing = [skip[t] for t in run.terrains if t in skip]
        if missing:
            done[run.name] = RunResult(run.name, "skipped", error="; ".join(missing))
        else:
            todo.append(run)
    with (kernel_threads(jobs), ThreadPoolExecutor(max_workers=max(1, jobs)) as pool,
          tqdm(total=len(todo), desc="notebooks", unit="run", disable=not progress) as bar,
          _kernel_bars(bar, progress)):
        # the runs marked first start first (the longest: the others fill the other
        # worker meanwhile); the record keeps the plan's order
        order = sorted(todo, key=lambda run: not run.first)
        futures = {pool.submit(execute_run, run, run_dir, data_dir, cwd): run for run in order}
        for future in as_completed(futures):
            result = future.result()
            if jobs > 1:  # kernels overlapped: a run's share of the children is unknown
                result.cpu_s = None
            done[result.name] = result
            bar.set_postfix_str(f"{result.name}: {result.status}")
            bar.update()
    return [done[run.name] for run in runs]


@contextlib.contextmanager
def _kernel_bars(bar: tqdm[NoReturn], progress: bool) -> Iterator[None]:
    """The notebooks' own bars (grid runs, sensor missions ..., :mod:`alte.progress`)
    shown here: on a terminal beside the bar over notebooks, on a log as lines."""
    if not progress:
        yield
        return
    show: Callable[[str], None] = (
        bar.set_postfix_str if sys.stderr.isatty()
        else Throttle(lambda line: tqdm.write(line, file=sys.stderr)))
    with Relay(show):
        yield


def _publish(reports: Path, run_dir: Path) -> list[Path]:
    point_latest(reports, run_dir)
    tables = publish_tables(run_dir / "tables", reports)
    listing = [(str(info.path.relative_to(reports)), info.record) for info in list_runs(reports)]
    write_html(reports / "index.html", top_index_html(listing, "latest"))
    return tables


def run_report(runs: Sequence[Run], reports: str | os.PathLike[str],
               data_dir: str | os.PathLike[str], *, quick: bool, jobs: int = 1,
               ensure: EnsureTerrain | None = None, progress: bool = True,
               cwd: str | os.PathLike[str] = REPO_ROOT, warmup: Warmup | None = None) -> Report:
    """Run ``runs`` into a new folder ``reports/runs/<stamp>`` and publish it as latest.

    ``warmup`` (:func:`~alte.lab.report.warm.start_warmup`) compiles the kernels while the
    terrains are simulated; the notebooks start when it has finished."""
    if not runs:
        raise ReportError("nothing to run: the plan selects no notebooks")
    reports, data_dir = Path(reports).resolve(), Path(data_dir).resolve()
    started = datetime.now(UTC)
    t0, cpu0 = time.perf_counter(), cpu_seconds(False) + cpu_seconds()
    load = os.getloadavg()[0]
    finish = warmup(progress) if warmup is not None else None
    skip = ensure_terrains(runs, data_dir, ensure, progress=progress)
    problems = sorted(skip.values()) + [p for p in [finish and finish()] if p]
    run_dir = new_run_dir(reports, started)
    results = _execute_all(runs, run_dir, data_dir, skip, jobs=jobs, progress=progress,
                           cwd=Path(cwd))
    tables = sorted((run_dir / "tables").glob("*.csv"))
    seconds = time.perf_counter() - t0
    cpu = cpu_seconds(False) + cpu_seconds() - cpu0
    record: JSONDict = {"mode": "quick" if quick else "full",
              "started": started.isoformat(timespec="seconds"), "seconds": seconds,
              "cpu_s": round(cpu, 1),
              "load_average": {"start": load, "end": os.getloadavg()[0]},
              "runs": [asdict(r) for r in results],
              "problems": problems, "tables": [t.name for t in tables]}
    write_html(run_dir / "index.html", run_index_html(record, run_dir, tables))
    write_record(run_dir, record)
    _publish(reports, run_dir)
    return Report(run_dir, results, problems, seconds, tables)
