"""A sweep's per-run work: runs that share a map are fed once and measured one by one.

Runs of one terrain, scans, seed and mapper whose settings differ only in the mapper's
view parameters (:attr:`alte.mappers.Mapper.view_params`: 3D-ALTE's ``min_pts``,
``min_pts_split``, ``occupancy_level``; 2D-ALTE's ``kappa``, ``min_pts``; Quadtree's
occupancy rule) or in set B make the same stored map: a :class:`MapGroup`.
:func:`run_group` feeds it through the pipeline as one run would be
(:func:`~alte.lab.studies.experiments.timed_run`: repeated when cheap; its
:class:`~alte.metrics.timing.Timing` and ``cost`` are every run's: the same calls on
the same data), then per run reads it with the run's
parameters (:meth:`~alte.mappers.Mapper.reread`) and measures it against the input's
:class:`~alte.metrics.reference.Reference` (the cloud's grids and the truth prepared
once per process and input). A run's row holds the values a run of its own would
(:func:`run_one`, one run as a group of one); ``wall_s`` and ``cpu_s`` are its share of
the work: its measurement plus an equal share of its group's feed.
"""

from __future__ import annotations

import functools
import json
import time
from collections.abc import Iterable
from dataclasses import dataclass

from alte.lab.studies.experiments import ground_truth, terrain, timed_run
from alte.lab.studies.obstacles import obstacle_columns, obstacle_options, obstacle_scores
from alte.lab.studies.sweep.runs import SweepRun
from alte.metrics.maps import TruthSettings, measure_map
from alte.metrics.reference import Reference
from alte.metrics.timing import Timing
from alte.pipeline import DomainPolicy, MapRun, MapSettings, Registered
from alte.registration.odometry import OdometrySettings
from alte.types import JSONDict

__all__ = ["MapGroup", "RunOutcome", "group_runs", "input_data", "run_group", "run_one"]

#: One run's result: (run id, its row or None, the exception or None).
RunOutcome = tuple[str, dict[str, object] | None, Exception | None]


@dataclass(frozen=True)
class MapGroup:
    """Runs that share one stored map (module docstring), in the order given."""

    runs: tuple[SweepRun, ...]

    def __len__(self) -> int:
        return len(self.runs)


def _resolved(run: SweepRun) -> dict[str, object]:
    """The run's mapper parameters, defaults filled in."""
    return run.cls.Settings.parse(run.params).as_dict()


def map_key(run: SweepRun) -> str:
    """What decides a run's stored map: everything but its view parameters and set B."""
    view = run.cls.view_params
    key = run.key()
    key["params"] = {k: v for k, v in _resolved(run).items() if k not in view}
    key.pop("truth")
    key.pop("set_b", None)
    return json.dumps(key, sort_keys=True, separators=(",", ":"))


def group_runs(runs: Iterable[SweepRun]) -> list[MapGroup]:
    """The runs as groups sharing a map, in order of each group's first run."""
    groups: dict[str, list[SweepRun]] = {}
    for run in runs:
        groups.setdefault(map_key(run), []).append(run)
    return [MapGroup(tuple(members)) for members in groups.values()]


#: What decides a run's registered input (:meth:`SweepRun.input_key`).
InputKey = tuple[str, int | None, int, float | None, str, bool, str]


def _registered(key: InputKey, data_dir: str) -> Registered:
    name, frames, seed, voxel, sensor, deskew, poses = key
    return terrain(name, data_dir, seed, frames, voxel=voxel, sensor=sensor, deskew=deskew,
                   odometry=OdometrySettings() if poses == "odometry" else None)


@functools.lru_cache(maxsize=2)
def _dataset(key: InputKey, data_dir: str) -> Registered:
    """Per-process memo over the on-disk registration cache (``DATA_DIR/.cache``)."""
    return _registered(key, data_dir)


def input_data(run: SweepRun, data_dir: str) -> Registered:
    """The run's terrain simulated when absent or out of date, and registered: every run
    with the same :meth:`~SweepRun.input_key` shares it (the registration cache)."""
    return _registered(run.input_key(), data_dir)


@functools.lru_cache(maxsize=2)
def _reference(key: InputKey, data_dir: str, truth: TruthSettings) -> Reference:
    """Per-process memo of the input's prepared cloud and truth (one per truth options)."""
    data = _dataset(key, data_dir)
    return Reference(data.cloud, ground_truth(data), truth)


def _inputs(run: SweepRun, data_dir: str) -> tuple[Registered, Reference]:
    """The run's registered input and its reference (a fresh per-leaf memory), both from
    this process's memo: the sweep ensured every input before its first map (``_ensure``),
    so a map group does not build the terrain and read the registration cache again."""
    key = run.input_key()
    return _dataset(key, data_dir), _reference(key, data_dir, run.truth).fresh()


def _row(run: SweepRun, data: Registered, measured: tuple[dict[str, float], JSONDict],
         cost: tuple[float, float]) -> dict[str, object]:
    metrics, obstacles = measured
    return {
        "run_id": run.run_id, "terrain": run.terrain, "frames_requested": run.frames or 0,
        "seed": run.seed, "mapper": run.mapper,
        "params_json": json.dumps(dict(run.params), sort_keys=True),
        **{f"p_{k}": v for k, v in run.params.items()},
        "domain": run.domain, "set_b": str(run.set_b), "sensor": run.sensor, "deskew": run.deskew,
        "poses": run.poses,
        "frames": len(data), "points": len(data.cloud),
        **{k: v for k, v in metrics.items() if k != "elapsed_s"}, **obstacles,
        "cost_unit": run.cls.cost_unit.value, "dims": run.cls.dims,
        "elapsed_s": float(metrics["elapsed_s"]), "wall_s": cost[0], "cpu_s": cost[1],
    }


def _measure(made: tuple[MapRun, Timing], run: SweepRun, data: Registered,
             reference: Reference) -> tuple[dict[str, float], JSONDict]:
    """The metrics of the map ``made`` (and its time) read with ``run``'s parameters, and
    its obstacle columns."""
    result, timing = made
    fed, mine = result.mapper.params.as_dict(), _resolved(run)
    changes = {k: mine[k] for k in run.cls.view_params if mine[k] != fed[k]}
    mapper = result.mapper.reread(**changes) if changes else result.mapper
    cells = mapper.cells()  # listed once for every metric
    metrics = measure_map(mapper, data.cloud, elapsed_s=timing, truth=reference.truth,
                          options=run.truth, set_b=run.set_b, reference=reference,
                          cells=cells).flat()
    options = obstacle_options(run.terrain) if run.obstacles else None
    return metrics, obstacle_columns(obstacle_scores(data, cells, mapper.dims, options))


def run_group(group: MapGroup, data_dir: str) -> list[RunOutcome]:
    """Feed the group's map once and measure it for each run (module docstring); a
    failure is that run's (or, in the feed, every run's) exception, returned."""
    start, cpu = time.perf_counter(), time.process_time()
    first = group.runs[0]
    try:
        data, reference = _inputs(first, data_dir)
        made = timed_run(data, MapSettings(first.cls, dict(first.params),
                                       domain=DomainPolicy(first.domain)))
    except Exception as err:  # a failed map fails its runs; the sweep goes on
        return [(r.run_id, None, err) for r in group.runs]
    share = ((time.perf_counter() - start) / len(group), (time.process_time() - cpu) / len(group))
    out: list[RunOutcome] = []
    for run in group.runs:
        start, cpu = time.perf_counter(), time.process_time()
        try:
            measured = _measure(made, run, data, reference)
        except Exception as err:  # a failed run is reported, the others go on
            out.append((run.run_id, None, err))
            continue
        cost = (share[0] + time.perf_counter() - start, share[1] + time.process_time() - cpu)
        out.append((run.run_id, _row(run, data, measured, cost), None))
    return out


def run_one(run: SweepRun, data_dir: str) -> dict[str, object]:
    """Map one run's terrain and return its flat row (keys, ``p_*`` params, metrics, and
    its cost: ``wall_s`` and ``cpu_s``, the CPU seconds of every thread of the process,
    which other load on the machine does not inflate). Raises what the run raised."""
    (_, row, error), = run_group(MapGroup((run,)), data_dir)
    if error is not None:
        raise error
    assert row is not None  # no error: a row
    return row
