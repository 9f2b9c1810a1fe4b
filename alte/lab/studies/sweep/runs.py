"""A sweep's runs: one :class:`SweepRun` per map to make and measure, as a spec plans them.

Every run has a stable :attr:`SweepRun.run_id`, the sha256 of its canonical JSON, so a
resumed sweep recognises runs it has already finished. :func:`plan_variants` lists the
base grid's runs and every ablation variant's (:mod:`~alte.lab.studies.sweep.variants`).
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
from collections.abc import Mapping
from dataclasses import dataclass, field

from alte.lab.studies.sweep.spec import SweepSpec
from alte.lab.studies.sweep.variants import Variant
from alte.mappers import Mapper
from alte.metrics.maps import MapPointSet, TruthSettings

__all__ = ["SweepRun", "plan_runs", "plan_variants"]


@dataclass(frozen=True)
class SweepRun:
    """One map to make and measure: the mapper's class and its ``params`` as the spec gives
    them (type-coerced)."""

    terrain: str
    frames: int | None
    seed: int
    cls: type[Mapper]
    params: Mapping[str, object]
    voxel: float | None = None
    truth: TruthSettings = field(default_factory=TruthSettings)
    domain: str = "auto"
    set_b: MapPointSet = MapPointSet.CORNERS
    sensor: str = "thesis"
    deskew: bool = True
    obstacles: bool = False
    poses: str = "recorded"

    @property
    def mapper(self) -> str:
        """The mapper's name."""
        return self.cls.name

    def key(self) -> dict[str, object]:
        """Everything that determines the run's result, JSON-ready (``domain``, ``set_b``,
        ``sensor``, ``deskew``, ``obstacles`` and ``poses`` only when not the default, so
        earlier runs keep their ids)."""
        key: dict[str, object] = {"terrain": self.terrain, "frames": self.frames, "seed": self.seed,
               "mapper": self.mapper, "params": dict(sorted(self.params.items())),
               "voxel": self.voxel, "truth": dataclasses.asdict(self.truth)}
        if self.domain != "auto":
            key["domain"] = self.domain
        if self.set_b != MapPointSet.CORNERS:
            key["set_b"] = str(self.set_b)
        if self.sensor != "thesis":
            key["sensor"] = self.sensor
        if not self.deskew:
            key["deskew"] = False
        if self.obstacles:
            key["obstacles"] = True
        if self.poses != "recorded":
            key["poses"] = self.poses
        return key

    def input_key(self) -> tuple[str, int | None, int, float | None, str, bool, str]:
        """What decides the run's registered input (terrain, scans, seed, voxel, sensor,
        deskew, poses): runs with equal keys share one simulation and registration."""
        return (self.terrain, self.frames, self.seed, self.voxel, self.sensor, self.deskew,
                self.poses)

    @property
    def run_id(self) -> str:
        """sha256 of the canonical JSON of :meth:`key` (stable across processes)."""
        text = json.dumps(self.key(), sort_keys=True, separators=(",", ":"))
        return hashlib.sha256(text.encode()).hexdigest()


def _variant_runs(spec: SweepSpec, variant: Variant) -> list[SweepRun]:
    """The runs of one variant in grid order (seed, terrain, mapper, row)."""
    terrains = variant.terrains or spec.terrains
    return [SweepRun(terrain, spec.frames, seed, grid.cls,
                     variant.params_for(grid.cls, params), spec.voxel, spec.truth,
                     variant.domain_for(grid.cls), variant.set_b_for(grid.cls),
                     variant.sensor, variant.deskew, spec.obstacles, variant.poses)
            for seed in spec.seeds for terrain in spec.terrains if terrain in terrains
            for grid in spec.mappers if terrain in grid.terrains for params in grid.rows]


def plan_variants(spec: SweepSpec) -> list[tuple[str, SweepRun]]:
    """(variant name, run) for the base grid, then every variant, in grid order; a run
    that several variants share (module :mod:`~alte.lab.studies.sweep.variants`) appears
    under each, a row listed twice within one variant once."""
    out: list[tuple[str, SweepRun]] = []
    for variant in (Variant(), *spec.variants):
        seen: set[str] = set()
        for run in _variant_runs(spec, variant):
            if run.run_id not in seen:
                seen.add(run.run_id)
                out.append((variant.name, run))
    return out


def plan_runs(spec: SweepSpec) -> list[SweepRun]:
    """Every distinct run of ``spec`` (base grid first, then the variants' own runs)."""
    runs: dict[str, SweepRun] = {}
    for _, run in plan_variants(spec):
        runs.setdefault(run.run_id, run)
    return list(runs.values())
