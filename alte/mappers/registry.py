"""The one place mapper names are resolved: the thesis' four built in, plugins by entry point.

Every other module carries a mapper class (or a spec that holds one); a name given by a
user (``--mapper``, a sweep spec, a notebook parameter) becomes a class here, once.

* **Built in**: Quadtree, Octomap, 2D-ALTE, 3D-ALTE.
* **Plugins**: the entry points of the group :data:`GROUP` (``alte.mappers``) of every
  installed distribution, declared in its ``pyproject.toml`` as
  ``[project.entry-points."alte.mappers"] NAME = "package.module:Class"``; and, for a
  mapper not packaged yet, the environment variable :data:`ENV` (``ALTE_MAPPERS``):
  ``module:Class`` items separated by commas, the module importable from ``sys.path``
  (it reaches the report's notebooks and workers, which inherit the environment).

Discovery reads package metadata only (:func:`importlib.metadata.entry_points`), once per
process; a plugin's module is imported when that mapper is first used or listed. A
plugin is checked against the contract when it is loaded (:func:`check_contract`), and
refused with a :class:`~alte.errors.ContractError` that names the plugin, where it came
from and every rule it breaks; a name taken by a built-in or by an earlier plugin is
refused the same way. :func:`refresh` forgets what was found (after installing one).
"""

from __future__ import annotations

import importlib
import os
import re
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from importlib import metadata
from typing import cast

from alte.errors import AlteError, ContractError, MapperError
from alte.mappers.alte2d import Alte2D
from alte.mappers.alte3d import Alte3D
from alte.mappers.base import API_VERSION, Mapper
from alte.mappers.contract import contract_problems
from alte.mappers.domain import Domain
from alte.mappers.octomap import Octomap
from alte.mappers.quadtree import Quadtree
from alte.params import Record

__all__ = ["BUILTIN", "ENV", "GROUP", "MapperEntry", "builtin", "check_contract", "classes",
           "create", "describe", "entries", "make_mapper", "names", "plugins", "refresh",
           "refused", "resolve", "title"]

#: The entry-point group plugins declare their mappers in.
GROUP = "alte.mappers"
#: Environment variable naming mapper classes (``module:Class``, comma separated).
ENV = "ALTE_MAPPERS"
#: The thesis' four, in the thesis' order of chapter 3.
BUILTIN: tuple[type[Mapper], ...] = (Quadtree, Octomap, Alte2D, Alte3D)
_TARGET = re.compile(r"^[A-Za-z_][\w.]*:[A-Za-z_][\w.]*$")


@dataclass(frozen=True)
class MapperEntry:
    """A mapper the registry knows: its name, ``module:Class`` and where it came from
    (``built-in``, ``DISTRIBUTION VERSION`` or the environment variable)."""

    name: str
    target: str
    origin: str

    @property
    def builtin(self) -> bool:
        """True for the thesis' four."""
        return self.origin == "built-in"

    def where(self) -> str:
        """The entry in words, for messages."""
        if self.builtin:
            return f"built-in mapper {self.name!r}"
        if self.origin == ENV:
            return f"mapper {self.target} (from {ENV})"
        return (f"mapper plugin {self.name!r} (entry point {GROUP}: {self.name} = "
                f"{self.target}, from {self.origin})")

    def load(self) -> type[Mapper]:
        """Import the class and check it against the contract."""
        module, _, attr = self.target.partition(":")
        try:
            found: object = importlib.import_module(module)
            for part in attr.split("."):
                found = getattr(found, part)
        except Exception as err:  # a plugin's import may fail in any way: say which
            raise ContractError(f"{self.where()}: cannot load {self.target} "
                                f"({type(err).__name__}: {err})") from err
        check_contract(found, self.where())
        cls = cast("type[Mapper]", found)  # check_contract refuses anything else
        if self.origin != ENV and cls.name != self.name:
            raise ContractError(f"{self.where()}: the class is named {cls.name!r}; the "
                                f"entry point must carry the class's name")
        return cls


def check_contract(cls: object, where: str | None = None) -> None:
    """Raise :class:`ContractError` listing every rule of the class-level contract
    (:mod:`alte.mappers.api`) that ``cls`` breaks; ``where`` names it in the message.
    :func:`alte.testing.check_mapper` checks the behaviour as well."""
    problems = contract_problems(cls)
    if problems:
        label = where or getattr(cls, "__qualname__", repr(cls))
        raise ContractError(f"{label} breaks the mapper contract (version {API_VERSION}): "
                            + "; ".join(problems))


_BUILTIN = {cls.name: MapperEntry(cls.name, f"{cls.__module__}:{cls.__qualname__}",
                                  "built-in") for cls in BUILTIN}


@dataclass
class _State:
    """What this process found: entries by name (None: not looked yet), refusals, and the
    classes loaded."""

    found: dict[str, MapperEntry] | None = None
    refused: dict[str, str] = field(default_factory=dict)
    loaded: dict[str, type[Mapper]] = field(default_factory=lambda: {c.name: c for c in BUILTIN})


_STATE = _State()
_refused = _STATE.refused
_loaded = _STATE.loaded


def _from_entry_points() -> Iterable[MapperEntry]:
    for point in sorted(metadata.entry_points(group=GROUP), key=lambda p: p.name):
        dist = point.dist
        origin = f"{dist.name} {dist.version}" if dist is not None else "an unknown distribution"
        yield MapperEntry(point.name, point.value, origin)


def _from_environment() -> Iterable[MapperEntry]:
    for item in filter(None, (i.strip() for i in os.environ.get(ENV, "").split(","))):
        attr = item.partition(":")[2]
        yield MapperEntry(attr.rpartition(".")[2].lower() if attr else item, item, ENV)


def _discover() -> dict[str, MapperEntry]:
    """Every entry (built-ins first), refusals noted in ``_refused``; metadata only."""
    if _STATE.found is None:
        found = dict(_BUILTIN)
        for entry in (*_from_entry_points(), *_from_environment()):
            if not _TARGET.match(entry.target):
                _refused[entry.name] = (f"{entry.where()}: {entry.target!r} is not "
                                        "'module:Class'")
            elif entry.name in found:
                _refused[f"{entry.name} ({entry.origin})"] = (
                    f"{entry.where()}: the name {entry.name!r} is taken by "
                    f"{found[entry.name].where()}")
            else:
                found[entry.name] = entry
        _STATE.found = found
    return _STATE.found


def _load_environment() -> None:
    """Import the classes :data:`ENV` names: their names are the classes' own."""
    found = _discover()
    for key, entry in list(found.items()):
        if entry.origin != ENV or key in _loaded:
            continue
        del found[key]
        try:
            cls = entry.load()
        except ContractError as err:
            _refused[entry.target] = str(err)
            continue
        if cls.name in found:
            _refused[entry.target] = (f"{entry.where()}: the name {cls.name!r} is taken by "
                                      f"{found[cls.name].where()}")
            continue
        found[cls.name] = MapperEntry(cls.name, entry.target, ENV)
        _loaded[cls.name] = cls


def refresh() -> None:
    """Forget discovered plugins (the next use finds them again)."""
    _STATE.found = None
    _refused.clear()
    for name in [n for n in _loaded if n not in _BUILTIN]:
        del _loaded[name]


def entries() -> tuple[MapperEntry, ...]:
    """Every mapper the registry knows, built-ins first (plugins not imported, except
    those named by :data:`ENV`, whose names are their classes')."""
    _load_environment()
    return tuple(_discover().values())


def refused() -> dict[str, str]:
    """Plugins refused at discovery (name taken, malformed target): key -> message."""
    entries()
    return dict(_refused)


def names() -> tuple[str, ...]:
    """The names of every mapper, built-ins first."""
    return tuple(e.name for e in entries())


def resolve(name: str) -> type[Mapper]:
    """The class registered as ``name`` (a plugin is loaded and checked on first use); an
    unknown name lists the valid ones, a refused plugin says why."""
    if name in _loaded:
        return _loaded[name]
    known = {e.name: e for e in entries()}
    if name not in known:
        why = [msg for key, msg in _refused.items() if key.split(" ")[0] == name]
        if why:
            raise ContractError(why[0])
        raise MapperError(f"unknown mapper {name!r}; valid: {', '.join(known)}")
    if name not in _loaded:
        _loaded[name] = known[name].load()
    return _loaded[name]


def title(name: str) -> str:
    """The display name of the mapper registered as ``name`` ("2D-ALTE"); the name itself
    for one this process does not know or cannot load (a table made elsewhere)."""
    try:
        return resolve(name).title
    except AlteError:
        return name


def builtin(cls: type[Mapper]) -> bool:
    """True for the thesis' four."""
    return cls in BUILTIN


def classes(*, plugins: bool = True) -> tuple[type[Mapper], ...]:
    """Every mapper class (built-ins first; ``plugins``: every plugin loaded and checked,
    a refused one raising :class:`ContractError`)."""
    if not plugins:
        return BUILTIN
    return tuple(resolve(name) for name in names())


def plugins(dims: int | None = None) -> tuple[type[Mapper], ...]:
    """Every plugin's class (loaded and checked; ``dims``: only 2D or 3D maps)."""
    return tuple(cls for cls in classes() if not builtin(cls)
                 and (dims is None or cls.dims == dims))


def create(mapper: str | type[Mapper], params: Mapping[str, object] | Record | None = None, /,
           *, domain: Domain | None = None, **given: object) -> Mapper:
    """Construct ``mapper`` (a class, or a name resolved here) with validated ``params`` (a
    mapping or record, and/or keywords) and, where the mapper uses one, its ``domain``. A
    record of the mapper's own ``Settings`` with no keywords is used as it is."""
    cls = resolve(mapper) if isinstance(mapper, str) else mapper
    if isinstance(params, cls.Settings) and not given:
        made: object = cls(domain, record=params)
    else:
        merged = params.as_dict() if isinstance(params, Record) else dict(params or {})
        made = cls(domain, **{**merged, **given})
    if not isinstance(made, Mapper):
        raise ContractError(f"{cls.__qualname__}: an instance does not meet the Mapper "
                            "protocol (run alte.testing.check_mapper on the class)")
    return made


#: A mapper by class or by registered name, with its parameters (:func:`create`).
make_mapper = create


def describe(entry: MapperEntry) -> dict[str, str]:
    """One row of ``alte info --mappers``: name, title, dims, origin and status (``ok`` or
    why the plugin is refused); loads the plugin."""
    try:
        cls = resolve(entry.name)
    except AlteError as err:
        return {"name": entry.name, "title": "", "dims": "", "origin": entry.origin,
                "target": entry.target, "status": str(err)}
    return {"name": cls.name, "title": cls.title, "dims": f"{cls.dims}D",
            "origin": entry.origin, "target": entry.target, "status": "ok"}
