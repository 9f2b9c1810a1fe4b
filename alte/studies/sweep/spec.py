"""Sweep specifications: a YAML grid of terrains x mappers x parameters, validated.

A spec names terrains, the scans kept per terrain (``frames``), the simulation
``seeds`` (or one ``seed``), where results go (``output``), per mapper a ``grid`` of
parameter lists (their cartesian product) and/or explicit ``rows``, and optionally
ablation ``variants`` (:mod:`alte.studies.sweep.variants`). The top-level scalars are a
:class:`SweepSettings` parameter record, checked and coerced like mapper parameters
(:mod:`alte.params`); errors name the spec and the key. The runs a spec plans are in
:mod:`~alte.studies.sweep.runs`.
"""

from __future__ import annotations

import itertools
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar, TypeVar

from alte.errors import AlteError, ParameterError
from alte.mappers import make_mapper
from alte.metrics.maps import TruthOptions
from alte.params import Record, param
from alte.sim import TERRAINS
from alte.studies.sweep.variants import Variant, parse_variants

__all__ = ["MapperGrid", "SweepSettings", "SweepSpec", "load_spec", "parse_spec"]

_MAPPER_KEYS = ("grid", "rows", "terrains")
_SCALARS = (bool, int, float, str)
_R = TypeVar("_R", bound=Record)


def _seed_list(value: object) -> bool:
    return isinstance(value, list | tuple) and bool(value) and all(
        isinstance(s, int) and not isinstance(s, bool) and s >= 0 for s in value)


@dataclass(frozen=True)
class SweepSettings(Record):
    """The scalar settings of a sweep spec's top level (and of :func:`override`)."""

    OWNER: ClassVar[str] = "sweep"
    name: str | None = param(None, help="the sweep's name (default: the spec file's stem)")
    frames: int | None = param(None, lambda v: v >= 1, "frames >= 1",
                               "scans kept per terrain (None: every scan)")
    seed: int | None = param(None, lambda v: v >= 0, "seed >= 0", "one simulation seed")
    seeds: tuple[int, ...] | None = param(None, _seed_list, "a non-empty list of integers >= 0",
                                          "several simulation seeds (not with seed)")
    voxel: float | None = param(None, lambda v: v > 0, "voxel > 0",
                                "voxel filter of the registered cloud (m; None: unfiltered)")
    data_dir: str = param("data", help="folder of the simulated terrains")
    output: str | None = param(None, help="results folder (default: reports/sweeps/NAME)")
    obstacles: bool = param(False, help="also score each map's obstacle identification "
                                        "against the simulator's objects")

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.seeds is None:
            return
        if self.seed is not None:
            raise ParameterError(f"{self.OWNER}: seeds: give either seed or seeds, not both")
        object.__setattr__(self, "seeds", tuple(dict.fromkeys(self.seeds)))  # distinct, in order

    def seed_list(self) -> tuple[int, ...]:
        """The seeds to run: ``seeds``, else ``seed`` alone, else seed 0."""
        if self.seeds is not None:
            return self.seeds
        return (0 if self.seed is None else self.seed,)


_TOP_KEYS = (*SweepSettings.names(), "terrains", "truth", "mappers", "variants")


@dataclass(frozen=True)
class MapperGrid:
    """A mapper's parameter rows (grid product and explicit rows) and its terrains."""

    mapper: str
    rows: tuple[Mapping[str, Any], ...]
    terrains: tuple[str, ...]


@dataclass(frozen=True)
class SweepSpec:
    """A validated sweep (see the module docstring); ``source`` names it in messages."""

    name: str
    terrains: tuple[str, ...]
    mappers: tuple[MapperGrid, ...]
    frames: int | None = None
    seeds: tuple[int, ...] = (0,)
    voxel: float | None = None
    data_dir: str = "data"
    output: str = ""
    truth: TruthOptions = field(default_factory=TruthOptions)
    source: str = "spec"
    variants: tuple[Variant, ...] = ()
    obstacles: bool = False


def _fail(source: str, key: str, message: str) -> ParameterError:
    return ParameterError(f"{source}: {key}: {message}")


def _check_keys(source: str, where: str, given: Mapping[str, Any], valid: Sequence[str]) -> None:
    unknown = sorted(set(map(str, given)) - set(valid))
    if unknown:
        raise _fail(source, where, f"unknown key(s) {', '.join(unknown)}; valid: "
                    f"{', '.join(valid)}")


def _terrains(source: str, key: str, value: Any) -> tuple[str, ...]:
    names = [value] if isinstance(value, str) else value
    if not isinstance(names, list) or not names:
        raise _fail(source, key, f"{value!r} must be a terrain name or a non-empty list")
    bad = [n for n in names if n not in TERRAINS]
    if bad:
        raise _fail(source, key, f"unknown terrain(s) {bad}; valid: {', '.join(TERRAINS)}")
    return tuple(dict.fromkeys(names))


def _record(source: str, record: type[_R], given: Mapping[str, object]) -> _R:
    """``record`` parsed from ``given``; its errors (naming its owner and the key, as in
    ``sweep: frames=0 out of range``) are prefixed with the spec's source."""
    try:
        return record.parse(given)
    except ParameterError as err:
        raise ParameterError(f"{source}: {err}") from err


def _truth(source: str, value: Any) -> TruthOptions:
    if value is None:
        return TruthOptions()
    if not isinstance(value, Mapping):
        raise _fail(source, "truth", f"{value!r} must be a mapping")
    return _record(source, TruthOptions, {str(k): v for k, v in value.items()})


def _grid_rows(source: str, key: str, grid: Any) -> list[dict[str, Any]]:
    if not isinstance(grid, Mapping) or not grid:
        raise _fail(source, key, f"{grid!r} must map parameter names to lists of values")
    lists = {}
    for name, given in grid.items():
        values = given if isinstance(given, list) else [given]
        if not values:
            raise _fail(source, f"{key}.{name}", "empty list of values")
        lists[str(name)] = values
    return [dict(zip(lists, combo, strict=True)) for combo in itertools.product(*lists.values())]


def _coerce_row(source: str, key: str, mapper: str, row: Any) -> dict[str, Any]:
    """Validate one parameter row by constructing the mapper; values come back coerced."""
    if not isinstance(row, Mapping):
        raise _fail(source, key, f"{row!r} must map parameter names to values")
    for name, value in row.items():
        if not isinstance(value, _SCALARS):
            raise _fail(source, f"{key}.{name}", f"{value!r} must be a number, string or bool")
    try:
        resolved = make_mapper(mapper, row).params.as_dict()
    except AlteError as err:
        raise _fail(source, key, str(err)) from err
    return {str(name): resolved[name] for name in row}


def _mapper(source: str, name: str, body: Any, terrains: tuple[str, ...]) -> MapperGrid:
    key = f"mappers.{name}"
    if not isinstance(body, Mapping) or not ({"grid", "rows"} & set(body)):
        raise _fail(source, key, "needs a 'grid' of parameter lists and/or explicit 'rows'")
    _check_keys(source, key, body, _MAPPER_KEYS)
    rows = _grid_rows(source, f"{key}.grid", body["grid"]) if "grid" in body else []
    explicit = body.get("rows", [])
    if not isinstance(explicit, list):
        raise _fail(source, f"{key}.rows", f"{explicit!r} must be a list of parameter mappings")
    rows += explicit
    coerced = [_coerce_row(source, key, name, row) for row in rows]
    own = _terrains(source, f"{key}.terrains", body["terrains"]) if "terrains" in body else terrains
    outside = sorted(set(own) - set(terrains))
    if outside:
        raise _fail(source, f"{key}.terrains", f"{outside} not in the top-level terrains")
    return MapperGrid(name, tuple(coerced), own)


def parse_spec(raw: Any, source: str = "spec") -> SweepSpec:
    """Validate a spec mapping (as read from YAML); errors name ``source`` and the key."""
    if not isinstance(raw, Mapping):
        raise ParameterError(f"{source}: expected a mapping of sweep settings, got {raw!r}")
    _check_keys(source, "top level", raw, _TOP_KEYS)
    for key in ("terrains", "mappers"):
        if key not in raw:
            raise _fail(source, key, "missing (required)")
    terrains = _terrains(source, "terrains", raw["terrains"])
    if not isinstance(raw["mappers"], Mapping) or not raw["mappers"]:
        raise _fail(source, "mappers", "must map mapper names to their grids")
    settings = _record(source, SweepSettings,
                       {k: raw[k] for k in SweepSettings.names() if k in raw})
    name = settings.name or Path(source).stem
    mappers = tuple(_mapper(source, str(m), body, terrains) for m, body in raw["mappers"].items())
    return SweepSpec(
        name=name, terrains=terrains, mappers=mappers, frames=settings.frames,
        seeds=settings.seed_list(), voxel=settings.voxel, data_dir=settings.data_dir,
        output=settings.output or f"reports/sweeps/{name}",
        truth=_truth(source, raw.get("truth")), source=source,
        variants=parse_variants(source, raw.get("variants"), terrains,
                                tuple(g.mapper for g in mappers)),
        obstacles=settings.obstacles)


def load_spec(path: str | os.PathLike[str]) -> SweepSpec:
    """Read and validate a YAML sweep spec."""
    import yaml

    path = Path(path)
    try:
        raw = yaml.safe_load(path.read_text())
    except OSError as err:
        raise ParameterError(f"sweep spec {path}: cannot read it ({err.strerror})") from err
    except yaml.YAMLError as err:
        raise ParameterError(f"sweep spec {path}: invalid YAML ({err})") from err
    return parse_spec(raw, str(path))
