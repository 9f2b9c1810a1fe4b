"""Rows 1, 2, 3 and 5: mapper speed, memory and latency against their peers.

Row 1/2: our Octomap (``backend=native``) and the C++ OctoMap through ``pyoctomap``
insert the same scans (same origins, max range and sensor model), interleaved pass
by pass; the last map of each gives the Jaccard index and the memory figures.
Row 3: batch builds at the chapter 4 parameters against ``numpy.argsort`` of as many
float64 keys (the floor of any sort-based build). Row 5: per-frame ``insert``
latency of every incremental mapper against one VLP-16 rotation (100 ms).

Rows 3 and 5 take every registered mapper (plugins included, :mod:`alte.mappers.registry`):
a 2D map on the landing terrain, a 3D map on the navigation one, with the thesis'
chapter 4 parameters for the thesis' four and a plugin's defaults.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from functools import partial
from typing import TYPE_CHECKING, Generic, Protocol, TypeVar

import numpy as np
from numpy.typing import NDArray
from tqdm.auto import tqdm

from alte.lab.studies.thesis.numbers import mapper_params
from alte.types import JSONDict
from bench.core import LIMITS, Context, Result
from bench.timing import interleave, measure
from bench.workload import Points, Scan

if TYPE_CHECKING:
    from alte.mappers import Mapper, Octomap
    from alte.mappers.domain import Domain
    from alte.params import Record

__all__ = [
    "JACCARD_MIN",
    "ROTATION_S",
    "Inserts",
    "MapperSetup",
    "Passes",
    "batch_builds",
    "insert_latencies",
    "insert_latency",
    "interleaved_passes",
    "mapper_setup",
    "octomap_memory",
    "octomap_passes",
    "octomap_speed",
    "terrain_of",
]

#: One VLP-16 rotation at 10 Hz: a mapper keeping up with the sensor inserts faster.
ROTATION_S = 0.1
#: Row 1's agreement bar between the backends.
JACCARD_MIN = 0.999
#: Row 3's bar per mapper (by name) where it is tighter than ``LIMITS[3]``.
BUILD_LIMITS = {"quadtree": 3.0}
NAV, LAN = "sim_nav_1", "sim_lan_2"


def terrain_of(cls: type[Mapper]) -> str:
    """The terrain a mapper is benchmarked on: its thesis case (3D: navigation, 2D:
    landing, chapter 4)."""
    return NAV if cls.dims == 3 else LAN


def bench_params(cls: type[Mapper]) -> dict[str, float]:
    """The chapter 4 parameters of one of the thesis' four on its terrain; a plugin's
    defaults (empty)."""
    return mapper_params(terrain_of(cls)).get(cls.name, {})


class Inserts(Protocol):
    """What a contender of :func:`interleaved_passes` does: insert one scan from its origin."""

    def insert(self, points: Points, origin: Points, /) -> None: ...


_M_co = TypeVar("_M_co", bound=Inserts, covariant=True)
_T = TypeVar("_T", bound=Inserts)


@dataclass(frozen=True, eq=False)
class Passes(Generic[_M_co]):
    """Per-frame insert seconds (wall, and CPU of the process) of every timed pass, and the
    last map, per contender."""

    latencies: dict[str, list[NDArray[np.float64]]]
    maps: Mapping[str, _M_co]
    cpu: dict[str, list[NDArray[np.float64]]]

    def totals(self, name: str) -> list[float]:
        """Seconds of each timed pass of ``name`` (sum of its frame latencies)."""
        return [float(t.sum()) for t in self.latencies[name]]


def insert_latencies(mapper: Inserts, scans: Sequence[Scan],
                     ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Insert every scan in order; wall and process CPU seconds of each ``insert`` call (the
    CPU time tells a loaded machine's waiting apart from the work)."""
    wall, cpu = np.empty(len(scans)), np.empty(len(scans))
    for i, (points, origin) in enumerate(scans):
        start, used = time.perf_counter(), time.process_time()
        mapper.insert(points, origin)
        wall[i], cpu[i] = time.perf_counter() - start, time.process_time() - used
    return wall, cpu


def interleaved_passes(makers: Mapping[str, Callable[[], _T]],
                       scans: Sequence[Scan], *, repeats: int,
                       warmup: int, progress: bool = False, desc: str = "passes"
                       ) -> Passes[_T]:
    """Fresh map per pass; contenders alternate pass by pass; warm-up passes discarded."""
    latencies: dict[str, list[NDArray[np.float64]]] = {name: [] for name in makers}
    cpu: dict[str, list[NDArray[np.float64]]] = {name: [] for name in makers}
    maps: dict[str, _T] = {}
    rounds = list(interleave(list(makers), warmup + repeats))
    for r, name in tqdm(rounds, desc=desc, unit="pass", disable=not progress, leave=False):
        mapper = makers[name]()
        seconds, used = insert_latencies(mapper, scans)
        if r >= warmup:
            latencies[name].append(seconds)
            cpu[name].append(used)
        maps[name] = mapper
    return Passes(latencies, maps, cpu)


@dataclass(frozen=True)
class MapperSetup:
    """A mapper as the bench makes it: its class, its :func:`bench_params` and, for
    mappers with a domain, the control volume's cube (as the pipeline gives it)."""

    cls: type[Mapper]
    params: dict[str, float]
    domain: Domain | None = None

    @property
    def name(self) -> str:
        """The mapper's name."""
        return self.cls.name

    def make(self, **given: object) -> Mapper:
        """A fresh mapper (``given``: further keywords, e.g. Octomap's ``backend``)."""
        from alte.mappers import make_mapper

        return make_mapper(self.cls, self.params, domain=self.domain, **given)


def mapper_setup(ctx: Context, cls: type[Mapper]) -> MapperSetup:
    """How the bench makes ``cls`` (:class:`MapperSetup`)."""
    from alte.mappers import DomainUse
    from alte.mappers.domain import Domain
    from alte.types import Box

    if cls.domain_use is DomainUse.UNUSED:
        return MapperSetup(cls, bench_params(cls))
    return MapperSetup(cls, bench_params(cls),
                       Domain.over(Box.of(ctx.workload(terrain_of(cls)).bounds)))


def octomap_passes(ctx: Context) -> Passes[Octomap]:
    """Native and reference Octomap over the same scans (memoised: rows 1, 2, 4, 5 share it)."""
    from alte.mappers import Octomap

    def octomap(setup: MapperSetup, backend: str) -> Octomap:
        mapper = setup.make(backend=backend)
        assert isinstance(mapper, Octomap), "the setup makes an Octomap"
        return mapper

    def run() -> Passes[Octomap]:
        setup = mapper_setup(ctx, Octomap)
        makers = {b: partial(octomap, setup, b) for b in ("native", "reference")}
        cfg = ctx.config
        return interleaved_passes(makers, ctx.scans(NAV), repeats=cfg.repeats,
                                  warmup=cfg.warmup, progress=cfg.progress, desc="octomap")

    return ctx.memo("octomap-passes", run)


def _jaccard(a: NDArray[np.uint64], b: NDArray[np.uint64]) -> float:
    union = np.union1d(a, b).size
    return np.intersect1d(a, b, assume_unique=True).size / union if union else 1.0


def octomap_speed(ctx: Context) -> list[Result]:
    """Row 1: native vs pyoctomap insertPointCloud, whole scan sequence; Jaccard of voxels."""
    passes = octomap_passes(ctx)
    native, reference = passes.maps["native"], passes.maps["reference"]
    jac = ctx.memo("octomap-jaccard", lambda: _jaccard(native.occupied_voxels(),
                                                       reference.occupied_voxels()))
    ours, peer = np.median(passes.totals("native")), np.median(passes.totals("reference"))
    scans = ctx.scans(NAV)
    leaves = (native.basis_functions, reference.basis_functions)
    detail: JSONDict = {
        "jaccard": jac, "frames": len(scans), "points": int(sum(len(p) for p, _ in scans)),
        "params": str(native.params), "native_s": passes.totals("native"),
        "reference_s": passes.totals("reference"), "leaves_native": leaves[0],
        "leaves_reference": leaves[1]}
    met = bool(ours / peer <= LIMITS[1] and jac >= JACCARD_MIN and leaves[0] == leaves[1])
    target = f"ratio <= {LIMITS[1]:.3f}, Jaccard >= {JACCARD_MIN}, equal leaf counts"
    return [Result(1, f"Octomap native vs pyoctomap, {NAV} ({len(scans)} frames)", float(ours),
                   float(peer), "s", target, met, detail)]


def octomap_memory(ctx: Context) -> list[Result]:
    """Row 2: bytes of the native map's arrays vs the reference's ``memoryUsage()``."""
    passes = octomap_passes(ctx)
    native, reference = passes.maps["native"], passes.maps["reference"]
    ours, peer = native.memory_bytes, reference.memory_bytes
    detail: JSONDict = {"leaves_native": native.basis_functions,
                        "leaves_reference": reference.basis_functions}
    return [Result(2, f"Octomap native memory, {NAV}", float(ours), float(peer), "B",
                   "ratio <= 1", bool(ours <= LIMITS[2] * peer), detail)]


def _build(cls: type[Mapper], params: Mapping[str, object] | Record, cloud: Points) -> None:
    """A fresh ``cls`` map built from ``cloud`` (the timed call of row 3)."""
    from alte.mappers import make_mapper

    make_mapper(cls, params).build(cloud)


def cloud_mappers() -> tuple[type[Mapper], ...]:
    """The mappers built from a bare cloud: all but those casting rays to free space
    (Octomap, whose build needs the scans' origins)."""
    from alte.mappers import registry

    return tuple(cls for cls in registry.classes() if not cls.free_space)


def batch_builds(ctx: Context) -> list[Result]:
    """Row 3: Quadtree, 2D-ALTE (and 2D plugins) on sim_lan_2, 3D-ALTE (and 3D plugins) on
    sim_nav_1 vs the argsort floor."""
    out = []
    for cls in cloud_mappers():
        name, terrain = cls.name, terrain_of(cls)
        cloud = ctx.workload(terrain).cloud
        params = bench_params(cls)
        keys = np.random.default_rng(0).random(len(cloud))
        times = measure({"ours": partial(_build, cls, params, cloud),
                         "peer": partial(np.argsort, keys)},
                        ctx.config.repeats, ctx.config.warmup)
        ratio = times["ours"].median / times["peer"].median
        limit = BUILD_LIMITS.get(name, LIMITS[3])
        out.append(Result(3, f"{name} build, {terrain} ({len(cloud)} pts)",
                          times["ours"].median, times["peer"].median, "s", f"ratio <= {limit:g}",
                          bool(ratio <= limit), {"params": params, "points": len(cloud),
                                                 "limit": limit,
                                                 **{k: s.as_dict() for k, s in times.items()}}))
    return out


def _latency_result(name: str, terrain: str, lat: list[NDArray[np.float64]],
                    cpu: list[NDArray[np.float64]],
                    extra: JSONDict) -> Result:
    p99 = [float(np.percentile(t, 99)) for t in lat]
    ours = float(np.median(p99)) * 1e3
    bound = LIMITS[5] * ROTATION_S * 1e3
    detail: JSONDict = {"p99_ms_per_pass": [v * 1e3 for v in p99], "frames": len(lat[0]),
                        "median_ms": float(np.median(np.concatenate(lat))) * 1e3,
                        "max_ms": float(np.max(np.concatenate(lat))) * 1e3,
                        "cpu_p99_ms": float(np.median([np.percentile(c, 99) for c in cpu])) * 1e3,
                        "cpu_median_ms": float(np.median(np.concatenate(cpu))) * 1e3, **extra}
    return Result(5, f"{name} insert p99, {terrain}", ours, ROTATION_S * 1e3, "ms",
                  f"p99 < {bound:g} ms", bool(ours < bound) and extra.get("same", True) is True,
                  detail)


def _same_as_batch(mapper: Mapper, frames: Sequence[Scan],
                   setup: MapperSetup) -> JSONDict:
    """Whether an incremental 2D map equals the batch build of its frames (same cells)."""
    batch = setup.make()
    batch.build(np.vstack([p for p, _ in frames]))
    a, b = mapper.cells(), batch.cells()
    same = bool(len(a) == len(b) and np.array_equal(a.centers[:, :2], b.centers[:, :2])
                and np.array_equal(a.sizes, b.sizes) and np.array_equal(a.occupied, b.occupied)
                and np.allclose(a.value, b.value, equal_nan=True, rtol=1e-9, atol=1e-9))
    return {"same": same, "leaves_incremental": len(a), "leaves_batch": len(b)}


def insert_latency(ctx: Context) -> list[Result]:
    """Row 5: p99 per-frame insert latency of each incremental mapper over EVERY frame
    (``--frames`` does not apply: later frames meet a bigger map), median over passes."""
    from alte.mappers import Octomap, registry

    cfg = ctx.config
    out = []
    for cls in registry.classes():
        if not cls.incremental:
            continue
        name, terrain = cls.name, terrain_of(cls)
        frames = ctx.workload(terrain).frames
        passes: Passes[Mapper]
        if cls is Octomap and cfg.frames is None and ctx.has("octomap-passes"):
            passes, key = octomap_passes(ctx), "native"  # row 1 already inserted every frame
        else:
            passes, key = interleaved_passes(
                {name: mapper_setup(ctx, cls).make}, frames,
                repeats=cfg.repeats, warmup=cfg.warmup, progress=cfg.progress, desc=name), name
        extra = (_same_as_batch(passes.maps[key], frames, mapper_setup(ctx, cls))
                 if cls.dims == 2 and registry.builtin(cls) else {})
        out.append(_latency_result(name, terrain, passes.latencies[key], passes.cpu[key], extra))
    return out
