"""The class-level rules of the mapper contract, as a list of what a class breaks.

:func:`contract_problems` checks what can be checked without making a map: the contract
version, the names, the parameter record and its defaults, every capability attribute's
type and coherence (view parameters and the settings grid name parameters of the
record, ``.npz`` among the exports) and the methods. The registry refuses a plugin
with any problem (:func:`alte.mappers.registry.check_contract`);
:func:`alte.testing.check_mapper` adds the behaviour (a map made and read).
"""

from __future__ import annotations

import dataclasses
import re
from collections.abc import Callable, Mapping

from alte.errors import AlteError
from alte.mappers.base import API_VERSION, Cost, Feed, adopt_v1_settings
from alte.mappers.domain import DomainUse
from alte.params import Record

__all__ = ["METHODS", "PROPERTIES", "contract_problems"]

#: Methods every mapper class defines.
METHODS = ("insert", "build", "cells", "cell_counts", "corners", "write_native", "reread")
#: Read-only values of an instance (properties, or attributes set by the constructor).
PROPERTIES = ("params", "domain", "points_outside", "cost", "basis_functions", "memory_bytes")
_NAME = re.compile(r"^[a-z][a-z0-9_]*$")


def _is(kind: type) -> Callable[[object], bool]:
    return lambda value: isinstance(value, kind)


def _strings(value: object) -> bool:
    return isinstance(value, frozenset) and all(isinstance(v, str) for v in value)


def _exports(value: object) -> bool:
    return _strings(value) and isinstance(value, frozenset) and ".npz" in value


#: Capability attributes: (name, test, what it must be).
_ATTRIBUTES: tuple[tuple[str, Callable[[object], bool], str], ...] = (
    ("name", lambda v: isinstance(v, str) and bool(_NAME.match(v)),
     "a lowercase identifier (letters, digits, _)"),
    ("title", lambda v: isinstance(v, str) and bool(v.strip()), "a non-empty str"),
    ("dims", lambda v: v in (2, 3) and not isinstance(v, bool), "2 or 3"),
    ("incremental", _is(bool), "a bool"),
    ("domain_use", _is(DomainUse), "a DomainUse"),
    ("default_feed", _is(Feed), "a Feed"),
    ("exports", _exports, "a frozenset of suffixes including '.npz'"),
    ("free_space", _is(bool), "a bool"),
    ("view_params", _strings, "a frozenset of parameter names"),
    ("cost_unit", _is(Cost), "a Cost"),
    ("layers", _strings, "a frozenset of layer names"),
    ("settings_grid", _is(Mapping), "a mapping of parameter names to tuples of values"),
)


def _version(cls: type) -> list[str]:
    version = getattr(cls, "api_version", None)
    if version is None:
        return [f"no api_version (this alte implements version {API_VERSION})"]
    if version != API_VERSION:
        return [f"written against mapper contract version {version!r}; this alte "
                f"implements version {API_VERSION}"]
    return []


def _params(cls: type) -> tuple[list[str], type[Record] | None]:
    record = getattr(cls, "Settings", None)
    if not (isinstance(record, type) and issubclass(record, Record)
            and dataclasses.is_dataclass(record)):
        return ["Settings must be a alte.params.Record dataclass (its parameter record)"], None
    try:
        record()
    except AlteError as err:
        return [f"Settings() must be valid with its defaults ({err})"], None
    except TypeError as err:
        return [f"every parameter of Settings needs a default ({err})"], None
    return [], record


def _grid(grid: Mapping[object, object], record: type[Record]) -> list[str]:
    out = []
    for key, values in grid.items():
        if key not in record.names():
            out.append(f"settings_grid names {key!r}, not a parameter of {record.__name__}")
        elif not isinstance(values, tuple | list) or not values:
            out.append(f"settings_grid[{key!r}] must be a non-empty tuple of values")
        else:
            for value in values:
                try:
                    record.parse({str(key): value})
                except AlteError as err:
                    out.append(f"settings_grid[{key!r}]: {err}")
    return out


def _coherence(cls: type, record: type[Record]) -> list[str]:
    out = []
    names = set(record.names())
    view: object = getattr(cls, "view_params", frozenset())
    if isinstance(view, frozenset) and view - names:
        out.append(f"view_params {sorted(view - names)} are not parameters of "
                   f"{record.__name__}")
    grid = getattr(cls, "settings_grid", {})
    if isinstance(grid, Mapping):
        out += _grid(grid, record)
    return out


def contract_problems(cls: object) -> list[str]:
    """Every class-level rule of the contract ``cls`` breaks (empty: none)."""
    if not isinstance(cls, type):
        return [f"{cls!r} is not a class"]
    adopt_v1_settings(cls)
    out = _version(cls)
    for name, test, what in _ATTRIBUTES:
        if not hasattr(cls, name):
            out.append(f"no class attribute {name} ({what})")
        elif not test(getattr(cls, name)):
            out.append(f"{name}={getattr(cls, name)!r} must be {what}")
    problems, record = _params(cls)
    out += problems
    if record is not None:
        out += _coherence(cls, record)
    out += [f"no method {m}()" for m in METHODS if not callable(getattr(cls, m, None))]
    return out
