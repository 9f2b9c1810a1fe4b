"""Experiments of thesis chapters 4-5 on top of the pipeline: map a terrain, measure the map.

Data flows one way: terrain name -> :func:`terrain` (simulated if absent, registered
once and cached under ``DATA_DIR/.cache``) -> :func:`measure` (one map through
:func:`alte.pipeline.run`, then :func:`alte.metrics.maps.measure_map`) -> :func:`sweep`
(a table of maps). Timing follows thesis 5.2.1 (mapper calls only), as a measured
quantity (:class:`alte.metrics.timing.Timing`): the first map of each mapper and feed in
a process is made once untimed (numba loads its kernels on first use: 0.2-0.7 s of CPU,
a hundred times a small map), and a map whose first timed run takes under
:data:`REPEAT_BELOW_S` CPU seconds is made :data:`REPEATS` times, its time the least.
Each mapper is fed as its protocol says (``Mapper.default_feed``: Quadtree once on the
final cloud, the others frame by frame), over the control volume's cube.
"""

from __future__ import annotations

import functools
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from alte.errors import ParameterError
from alte.lab.studies.thesis.numbers import SWEEPS, sweep_table
from alte.mappers import Mapper
from alte.metrics.maps import GroundTruth, MapMetrics, MapPointSet, TruthSettings, measure_map
from alte.metrics.reference import Reference
from alte.metrics.timing import Timing
from alte.params import Record
from alte.pipeline import (
    FrameSettings,
    InputKind,
    MapRun,
    MapSettings,
    PoseSource,
    Registered,
    open_input,
    prepare,
    run,
)
from alte.progress import bar as progress_bar
from alte.registration.odometry import OdometrySettings

__all__ = ["CACHE_DIR", "REPEATS", "REPEAT_BELOW_S", "Measured", "ground_truth", "measure",
           "reference_of", "sweep", "terrain", "timed_run"]

#: Where registrations are cached, inside the data folder (``DATA_DIR/.cache``).
CACHE_DIR = ".cache"
#: Runs of a cheap map (the least reading is its time: other processes only add to it;
#: three give a spread).
REPEATS = 3
#: A map whose first timed run takes less CPU than this is repeated (a whole mission's
#: map, seconds long, is timed once: its repeats would cost more than the rest of its row).
REPEAT_BELOW_S = 0.5
#: (mapper, feed) pairs this process has mapped with: their kernels are loaded.
_WARM: set[tuple[type[Mapper], str]] = set()


@dataclass(eq=False)
class Measured:
    """A map run and its metrics."""

    run: MapRun
    metrics: MapMetrics

    @property
    def mapper(self) -> Mapper:
        """The finished map."""
        return self.run.mapper

    @property
    def name(self) -> str:
        """Mapper name."""
        return self.run.info.mapper

    @property
    def params(self) -> Record:
        """The parameters the map was made with (defaults filled in)."""
        return self.run.info.params


def terrain(name: str, data_dir: str | os.PathLike[str] = "data", seed: int = 0,
            frames: int | None = None, *, voxel: float | None = None, sensor: str = "thesis",
            deskew: bool = True, odometry: OdometrySettings | None = None,
            progress: bool = False) -> Registered:
    """Terrain ``name`` registered (simulated first when absent; cached per spec and seed
    in ``DATA_DIR/.cache``): the one way a study turns a terrain into registered frames.

    ``frames`` keeps that many scans (a reduced mission ``NAME-Nf`` is simulated);
    ``voxel`` overrides the terrain's registration voxel; ``sensor``: a profile of
    :data:`alte.sim.profile.PROFILES` (its scans deskewed along the recorded poses unless
    ``deskew`` is False); ``odometry``: pose the scans by odometry with these settings
    instead (the whole mission is then simulated and ``frames`` of it kept).
    """
    from alte.sim import ensure_terrain
    from alte.sim.profile import PROFILES

    if sensor not in PROFILES:
        raise ParameterError(f"sensor {sensor!r}: expected one of {', '.join(PROFILES)}")
    folder = ensure_terrain(name, data_dir, seed, frames if odometry is None else None,
                            progress=progress, profile=PROFILES[sensor])
    spec = FrameSettings(frames=frames, voxel=voxel, deskew=deskew,
                     poses=PoseSource.AUTO if odometry is None else PoseSource.ODOMETRY,
                     odometry=odometry or OdometrySettings())
    return prepare(open_input(folder), spec, cache=Path(data_dir) / CACHE_DIR,
                   progress=progress)


@functools.lru_cache(maxsize=4)
def _truth(folder: str) -> GroundTruth | None:
    return open_input(folder).ground_truth()


def ground_truth(data: Registered) -> GroundTruth | None:
    """The terrain's true surface and control volume (loaded once per process); None for
    an input that is not a simulated terrain."""
    if data.source.kind is not InputKind.TERRAIN:
        return None
    return _truth(str(data.source.path))


def timed_run(data: Registered, spec: MapSettings, *, repeats: int = REPEATS,
              progress: bool = False) -> tuple[MapRun, Timing]:
    """Map ``data`` as ``spec`` says, timed as the module docstring says: the last run
    and the :class:`Timing` of the timed ones."""
    if repeats < 1:
        raise ParameterError(f"repeats={repeats}: expected at least 1")
    warm = (spec.cls, (spec.feed or spec.cls.default_feed).value)
    if warm not in _WARM:
        run(data, spec)
        _WARM.add(warm)
    result = run(data, spec, progress=progress)
    wall, cpu = [result.elapsed_s], [result.cpu_s]
    while len(wall) < repeats and cpu[0] < REPEAT_BELOW_S:
        result = run(data, spec)
        wall.append(result.elapsed_s)
        cpu.append(result.cpu_s)
    return result, Timing.of(wall, cpu)


def measure(data: Registered, mapper: str, params: Mapping[str, object] | None = None, *,
            truth: TruthSettings | None = None, spec: MapSettings | None = None,
            set_b: MapPointSet = MapPointSet.CORNERS, progress: bool = False,
            reference: Reference | None = None) -> Measured:
    """Map ``data`` with ``mapper`` and ``params`` and measure it (``truth``: also against
    the true surface; ``set_b``: the map's points of HD/MHD, see
    :class:`alte.metrics.maps.MapPointSet`). ``spec`` replaces
    the default map specification. The map is timed by :func:`timed_run`.
    ``reference``: :func:`reference_of` ``data`` and ``truth``, prepared once for several
    maps (the same values)."""
    chosen = spec or MapSettings(mapper, dict(params or {}))
    result, timing = timed_run(data, chosen, progress=progress)
    cells = result.mapper.cells()  # listed once for every metric
    metrics = measure_map(result.mapper, data.cloud, elapsed_s=timing,
                          truth=ground_truth(data) if truth is not None else None,
                          options=truth, set_b=set_b, cells=cells,
                          reference=None if reference is None else reference.fresh())
    return Measured(result, metrics)


def reference_of(data: Registered, truth: TruthSettings | None) -> Reference:
    """The cloud of ``data`` and, with ``truth``, its true surface, prepared once for
    every map :func:`measure` makes of it (:class:`~alte.metrics.reference.Reference`:
    the cloud's nearest-neighbour grids, the surface samples and what the sensor saw of
    them, the true heights under the 2D probes)."""
    return Reference(data.cloud, ground_truth(data) if truth is not None else None, truth)


def sweep(data: Registered, table: int, rows: Sequence[int] | None = None, *,
          extra: Mapping[str, object] | None = None, truth: TruthSettings | None = None,
          progress: bool = True) -> tuple[pd.DataFrame, list[Measured]]:
    """Run the parameter rows of table 5.``table`` (7, 8, 9 or 12) on ``data``.

    ``rows`` picks thesis rows by index (default: all six); ``extra`` adds fixed mapper
    parameters to every row (e.g. a ground plane). Returns the table (our metrics beside
    the ``thesis_*`` columns) and the measured maps, for figures.
    """
    if table not in SWEEPS:
        raise ParameterError(f"table 5.{table} is not a sweep; sweeps: {sorted(SWEEPS)}")
    spec = SWEEPS[table]
    chosen = list(range(len(spec["rows"]))) if rows is None else list(rows)
    bad = [r for r in chosen if not 0 <= r < len(spec["rows"])]
    if bad or not chosen:
        raise ParameterError(f"table 5.{table}: rows {bad or chosen} not in 0..5")
    thesis = sweep_table(table).iloc[chosen].reset_index(drop=True)
    reference = reference_of(data, truth)  # the cloud and truth prepared once
    runs = [measure(data, spec["mapper"], {**spec["rows"][r][0], **(extra or {})}, truth=truth,
                    reference=reference)
            for r in progress_bar(chosen, desc=f"table 5.{table}", unit="map",
                                  disable=not progress)]
    ours = pd.DataFrame([m.metrics.flat() for m in runs])
    ours.insert(0, "thesis_row", chosen)
    return pd.concat([thesis, ours], axis=1), runs
