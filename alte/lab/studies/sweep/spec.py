"""Sweep specifications: a YAML grid of terrains x mappers x parameters, validated.

A spec names terrains, the scans kept per terrain (``frames``), the simulation
``seeds`` (or one ``seed``), where results go (``output``), per mapper a ``grid`` of
parameter lists (their cartesian product) and/or explicit ``rows``, and optionally
ablation ``variants`` (:mod:`alte.lab.studies.sweep.variants`). With ``plugins: true`` (or
:func:`with_plugins`) every installed plugin mapper the spec does not list joins the
grid with its own ``settings_grid`` on every terrain (a plugin the spec lists keeps the
spec's rows). The top-level scalars are a
:class:`SweepSettings` parameter record, checked and coerced like mapper parameters
(:mod:`alte.params`); errors name the spec and the key. The runs a spec plans are in
:mod:`~alte.lab.studies.sweep.runs`.
"""

from __future__ import annotations

import dataclasses
import itertools
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import ClassVar, TypeVar

from alte.errors import AlteError, ParameterError
from alte.lab.studies.sweep.variants import Variant, parse_variants, spec_error
from alte.mappers import Mapper, registry
from alte.metrics.maps import TruthSettings
from alte.params import Record, param
from alte.sim import TERRAINS

__all__ = ["MapperGrid", "SweepSettings", "SweepSpec", "load_spec", "parse_spec", "with_plugins"]

_MAPPER_KEYS = ("grid", "rows", "terrains")
_SCALARS = (bool, int, float, str)
_R = TypeVar("_R", bound=Record)


def _seed_list(value: tuple[int, ...]) -> bool:
    return bool(value) and all(s >= 0 for s in value)


def _known(names: tuple[str, ...]) -> bool:
    """Non-empty names (built-in, or imported into the data folder: :func:`_terrains`
    checks which when the spec is read)."""
    return bool(names) and all(isinstance(n, str) and n for n in names)


def _imported(name: str, data_dir: str) -> bool:
    """Whether ``data_dir/NAME`` is a terrain imported with ``alte simulate TILE ...``."""
    return (Path(data_dir) / name / "scenario.json").is_file()


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
    plugins: bool = param(False, help="add every installed plugin mapper the spec does not "
                                      "list, with its own settings grid")

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
class MapperGrid(Record):
    """A mapper (its class) with its parameter rows (grid product and explicit rows,
    coerced by the mapper's own record) and its terrains."""

    OWNER: ClassVar[str] = "mapper grid"
    cls: type[Mapper]
    rows: tuple[Mapping[str, object], ...] = param((), help="its parameter rows")
    terrains: tuple[str, ...] = param((), _known, "known terrain names", "its terrains")

    @property
    def mapper(self) -> str:
        """The mapper's name."""
        return self.cls.name


@dataclass(frozen=True)
class SweepSpec(Record):
    """A validated sweep (see the module docstring): its :class:`SweepSettings` and what
    it runs; ``source`` names it in messages. ``name``, ``frames``, ``seeds``, ``voxel``,
    ``data_dir``, ``output`` and ``obstacles`` read the settings (``name`` and ``output``
    with their defaults filled in)."""

    OWNER: ClassVar[str] = "sweep"
    terrains: tuple[str, ...] = param((), _known, "known terrain names", "the terrains")
    mappers: tuple[MapperGrid, ...] = param((), help="each mapper's grid")
    settings: SweepSettings = field(default_factory=SweepSettings)
    truth: TruthSettings = field(default_factory=TruthSettings)
    source: str = param("spec", help="where the spec came from (its file)")
    variants: tuple[Variant, ...] = param((), help="the ablation variants")

    @property
    def name(self) -> str:
        """The sweep's name: given, else the spec file's stem."""
        return self.settings.name or Path(self.source).stem

    @property
    def frames(self) -> int | None:
        """Scans kept per terrain (None: every scan)."""
        return self.settings.frames

    @property
    def seeds(self) -> tuple[int, ...]:
        """The simulation seeds."""
        return self.settings.seed_list()

    @property
    def voxel(self) -> float | None:
        """Voxel filter of the registered cloud (m)."""
        return self.settings.voxel

    @property
    def data_dir(self) -> str:
        """Folder of the simulated terrains."""
        return self.settings.data_dir

    @property
    def output(self) -> str:
        """Results folder."""
        return self.settings.output or f"reports/sweeps/{self.name}"

    @property
    def obstacles(self) -> bool:
        """Whether obstacle identification is scored too."""
        return self.settings.obstacles


def _check_keys(source: str, where: str, given: Mapping[object, object],
                valid: Sequence[str]) -> None:
    unknown = sorted(set(map(str, given)) - set(valid))
    if unknown:
        raise spec_error(source, where, f"unknown key(s) {', '.join(unknown)}; valid: "
                         f"{', '.join(valid)}")


def _terrains(source: str, key: str, value: object, data_dir: str = "data") -> tuple[str, ...]:
    names = [value] if isinstance(value, str) else value
    if not isinstance(names, list) or not names:
        raise spec_error(source, key, f"{value!r} must be a terrain name or a non-empty list")
    bad = [n for n in names if n not in TERRAINS and not _imported(str(n), data_dir)]
    if bad:
        raise spec_error(source, key, f"unknown terrain(s) {bad}; valid: {', '.join(TERRAINS)}, "
                         f"or a terrain imported into {data_dir} (alte simulate TILE.laz)")
    return tuple(dict.fromkeys(names))


def _record(source: str, record: type[_R], given: Mapping[object, object]) -> _R:
    """``record`` parsed from ``given``; its errors (naming its owner and the key, as in
    ``sweep: frames=0 out of range``) are prefixed with the spec's source."""
    try:
        return record.parse({str(k): v for k, v in given.items()})
    except ParameterError as err:
        raise ParameterError(f"{source}: {err}") from err


def _truth(source: str, value: object) -> TruthSettings:
    if value is None:
        return TruthSettings()
    if not isinstance(value, Mapping):
        raise spec_error(source, "truth", f"{value!r} must be a mapping")
    return _record(source, TruthSettings, value)


def _grid_rows(source: str, key: str, grid: object) -> list[dict[str, object]]:
    if not isinstance(grid, Mapping) or not grid:
        raise spec_error(source, key, f"{grid!r} must map parameter names to lists of values")
    lists = {}
    for name, given in grid.items():
        values = given if isinstance(given, list) else [given]
        if not values:
            raise spec_error(source, f"{key}.{name}", "empty list of values")
        lists[str(name)] = values
    return [dict(zip(lists, combo, strict=True)) for combo in itertools.product(*lists.values())]


def _coerce_row(source: str, key: str, mapper: type[Mapper], row: object) -> dict[str, object]:
    """Validate one parameter row by the mapper's record; values come back coerced."""
    if not isinstance(row, Mapping):
        raise spec_error(source, key, f"{row!r} must map parameter names to values")
    for name, value in row.items():
        if not isinstance(value, _SCALARS):
            raise spec_error(source, f"{key}.{name}", f"{value!r} must be a number, string or "
                             "bool")
    try:
        resolved = mapper.Settings.parse({str(k): v for k, v in row.items()}).as_dict()
    except AlteError as err:
        raise spec_error(source, key, str(err)) from err
    return {str(name): resolved[str(name)] for name in row}


def _mapper(source: str, name: str, body: object, terrains: tuple[str, ...]) -> MapperGrid:
    key = f"mappers.{name}"
    try:
        cls = registry.resolve(name)  # the spec's names become classes here, once
    except AlteError as err:
        raise spec_error(source, key, str(err)) from err
    if not isinstance(body, Mapping) or not ({"grid", "rows"} & set(body)):
        raise spec_error(source, key, "needs a 'grid' of parameter lists and/or explicit "
                         "'rows'")
    _check_keys(source, key, body, _MAPPER_KEYS)
    rows: list[object] = list(_grid_rows(source, f"{key}.grid", body["grid"])
                              if "grid" in body else [])
    explicit = body.get("rows", [])
    if not isinstance(explicit, list):
        raise spec_error(source, f"{key}.rows", f"{explicit!r} must be a list of parameter "
                         "mappings")
    rows += explicit
    coerced = tuple(_coerce_row(source, key, cls, row) for row in rows)
    own = _terrains(source, f"{key}.terrains", body["terrains"]) if "terrains" in body else terrains
    outside = sorted(set(own) - set(terrains))
    if outside:
        raise spec_error(source, f"{key}.terrains", f"{outside} not in the top-level terrains")
    return MapperGrid(cls, coerced, own)


def with_plugins(spec: SweepSpec) -> SweepSpec:
    """``spec`` with a grid for every installed plugin mapper it does not list: the rows of
    the plugin's ``settings_grid`` (its defaults when empty) on every terrain of the spec."""
    listed = {g.cls for g in spec.mappers}
    grids = []
    for cls in registry.plugins():
        if cls in listed:
            continue
        key = f"plugin {cls.name} settings_grid"
        lists = {k: list(v) for k, v in cls.settings_grid.items()}
        rows = _grid_rows(spec.source, key, lists) if lists else [{}]
        grids.append(MapperGrid(cls, tuple(_coerce_row(spec.source, key, cls, r) for r in rows),
                                spec.terrains))
    return dataclasses.replace(spec, mappers=spec.mappers + tuple(grids))


def parse_spec(raw: object, source: str = "spec") -> SweepSpec:
    """Validate a spec mapping (as read from YAML); errors name ``source`` and the key."""
    if not isinstance(raw, Mapping):
        raise ParameterError(f"{source}: expected a mapping of sweep settings, got {raw!r}")
    _check_keys(source, "top level", raw, _TOP_KEYS)
    for key in ("terrains", "mappers"):
        if key not in raw:
            raise spec_error(source, key, "missing (required)")
    terrains = _terrains(source, "terrains", raw["terrains"], str(raw.get("data_dir", "data")))
    if not isinstance(raw["mappers"], Mapping) or not raw["mappers"]:
        raise spec_error(source, "mappers", "must map mapper names to their grids")
    settings = _record(source, SweepSettings,
                       {k: raw[k] for k in SweepSettings.names() if k in raw})
    mappers = tuple(_mapper(source, str(m), body, terrains) for m, body in raw["mappers"].items())
    spec = SweepSpec(
        terrains=terrains, mappers=mappers, settings=settings,
        truth=_truth(source, raw.get("truth")), source=source,
        variants=parse_variants(source, raw.get("variants"), terrains,
                                tuple(g.cls for g in mappers)))
    return with_plugins(spec) if settings.plugins else spec


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
