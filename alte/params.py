"""One way to declare and validate parameters: frozen dataclasses whose fields carry rules.

Mapper parameters, sweep settings, landing limits, benchmark settings and the report's
notebook parameters are all :class:`Record` subclasses. A field is declared with
:func:`param` (default, check, rule, help); values given as text (``--set k=v``, YAML,
notebook parameters) are coerced to the field's annotated type (numbers, text, booleans,
``Literal`` choices, enums, paths, tuples and nested records from mappings, as YAML gives
them), and every failure is a
:class:`~alte.errors.ParameterError` that names the owner, the parameter and the rule:
``quadtree: max_points=0 out of range (max_points >= 1)``, ``alte2d: unknown
parameter(s) kapa; valid: criterion, kappa, max_res, min_pts``.
"""

from __future__ import annotations

import dataclasses
import enum
import math
import types
import typing
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar, Generic, Literal, Self, TypeVar, get_args, get_origin, overload

from alte.errors import ParameterError

__all__ = ["Record", "Rule", "coerce", "key_values", "param", "required"]

_T = TypeVar("_T")
_V_contra = TypeVar("_V_contra", contravariant=True)

_TRUE = {"true", "1", "yes"}
_FALSE = {"false", "0", "no"}


def _always(_value: object) -> bool:
    return True


@dataclass(frozen=True)
class Rule(Generic[_V_contra]):
    """How one field is checked and explained: ``check(value)`` must hold; ``rule`` says what."""

    check: Callable[[_V_contra], bool] = _always
    rule: str = ""
    help: str = ""


# A None default takes its type from the field it declares (a check that accepts anything,
# like ``bool``, says nothing about it); a check sees the coerced value, never None.
@overload
def param(default: None, check: Callable[[object], bool], rule: str = "",
          help: str = "") -> _T | None: ...
@overload
def param(default: None, check: Callable[[_T], bool] = _always, rule: str = "",
          help: str = "") -> _T | None: ...
@overload
def param(default: _T, check: Callable[[_T], bool] = _always, rule: str = "",
          help: str = "") -> _T: ...
def param(default: object, check: Callable[[_T], bool] = _always, rule: str = "",
          help: str = "") -> object:
    """A :class:`Record` field with its default and validity rule; ``check`` sees the
    coerced value, never None (an optional field's None is always valid)."""
    return field(default=default, metadata={"rule": Rule(check, rule, help)})


def required(check: Callable[[Any], bool] = _always, rule: str = "",
             help: str = "") -> dict[str, Rule[Any]]:
    """The metadata of a :class:`Record` field without a default, with its rule:
    ``name: str = field(metadata=required(help="..."))`` (a plain ``field()`` call, so
    type checkers see the field as required)."""
    return {"rule": Rule(check, rule, help)}


def _bool(owner: str, name: str, value: object) -> bool:
    if isinstance(value, bool):
        return value
    text = str(value).strip().lower()
    if text not in _TRUE | _FALSE:
        raise ParameterError(f"{owner}: {name}={value!r} is not a boolean")
    return text in _TRUE


def _int(owner: str, name: str, value: object) -> int:
    if isinstance(value, bool):
        raise ParameterError(f"{owner}: {name}={value!r} is not a valid int")
    try:
        number = float(value) if isinstance(value, str) else value
    except ValueError as err:
        raise ParameterError(f"{owner}: {name}={value!r} is not a valid int") from err
    if isinstance(number, int):
        return number
    if not isinstance(number, float):
        raise ParameterError(f"{owner}: {name}={value!r} is not a valid int")
    if not math.isfinite(number) or not number.is_integer():
        raise ParameterError(f"{owner}: {name}={value!r} must be an integer")
    return int(number)


def _float(owner: str, name: str, value: object) -> float:
    if isinstance(value, bool) or not isinstance(value, str | int | float):
        raise ParameterError(f"{owner}: {name}={value!r} is not a valid float")
    try:
        number = float(value)
    except ValueError as err:
        raise ParameterError(f"{owner}: {name}={value!r} is not a valid float") from err
    if not math.isfinite(number):
        raise ParameterError(f"{owner}: {name}={number!r} must be finite")
    return number


def _enum(owner: str, name: str, kind: type[enum.Enum], value: object) -> enum.Enum:
    if isinstance(value, kind):
        return value
    try:
        return kind(value)
    except ValueError as err:
        valid = "|".join(str(m.value) for m in kind)
        raise ParameterError(f"{owner}: {name}={value!r} out of range ({valid})") from err


def _tuple(owner: str, name: str, kind: object, value: object) -> tuple[object, ...]:
    """A tuple from a list or tuple: ``tuple[X, ...]`` of any length, ``tuple[X, Y]`` fixed."""
    args = get_args(kind)
    if isinstance(value, str | bytes) or not isinstance(value, Sequence):
        raise ParameterError(f"{owner}: {name}={value!r} is not a list")
    items = list(value)
    if len(args) == 2 and args[1] is Ellipsis:
        kinds = [args[0]] * len(items)
    elif len(args) != len(items):
        raise ParameterError(f"{owner}: {name}={value!r}: expected {len(args)} values")
    else:
        kinds = list(args)
    return tuple(coerce(owner, f"{name}[{i}]", k, v)
                 for i, (k, v) in enumerate(zip(kinds, items, strict=True)))


def _record(owner: str, name: str, kind: type[Record], value: object) -> Record:
    """A nested record from a mapping (YAML), its errors prefixed with the field's name."""
    if isinstance(value, kind):
        return value
    if not isinstance(value, Mapping):
        raise ParameterError(f"{owner}: {name}={value!r} must be a mapping of "
                             f"{kind.OWNER} parameters")
    try:
        return kind.parse({str(k): v for k, v in value.items()})
    except ParameterError as err:
        raise ParameterError(f"{owner}: {name}: {err}") from err


def _text(owner: str, name: str, value: object) -> str:
    if not isinstance(value, str | int | float) or isinstance(value, bool):
        raise ParameterError(f"{owner}: {name}={value!r} is not a valid str")
    return str(value)


def _path(owner: str, name: str, value: object) -> Path:
    if not isinstance(value, str | Path):
        raise ParameterError(f"{owner}: {name}={value!r} is not a path")
    return Path(value)


_CONVERTERS: dict[object, Callable[[str, str, object], object]] = {
    bool: _bool, int: _int, float: _float, str: _text, Path: _path}


def coerce(owner: str, name: str, kind: object, value: object) -> object:
    """``value`` as the annotated type ``kind``: int, float, str, bool, Path, Literal, an
    enum, ``tuple[X, ...]``, a nested :class:`Record` (from a mapping), ``X | None``;
    other types pass unchanged."""
    origin = get_origin(kind)
    if origin in (types.UnionType, typing.Union):
        options = [k for k in get_args(kind) if k is not type(None)]
        if value is None or (isinstance(value, str) and value.strip().lower() in {"none", "null"}):
            return None
        return coerce(owner, name, options[0], value)
    if origin is Literal:
        allowed = get_args(kind)
        if value not in allowed:
            raise ParameterError(f"{owner}: {name}={value!r} out of range "
                                 f"({'|'.join(map(str, allowed))})")
        return value
    if origin is tuple:
        return _tuple(owner, name, kind, value)
    return _plain(owner, name, kind, value)


def _plain(owner: str, name: str, kind: object, value: object) -> object:
    """``value`` as a plain (not generic) type: a scalar, a path, an enum or a record."""
    if kind in _CONVERTERS:
        return _CONVERTERS[kind](owner, name, value)
    if isinstance(kind, type) and issubclass(kind, enum.Enum):
        return _enum(owner, name, kind, value)
    if isinstance(kind, type) and issubclass(kind, Record):
        return _record(owner, name, kind, value)
    return value


_HINTS: dict[type, dict[str, object]] = {}


def _hints(cls: type) -> dict[str, object]:
    """A record class's resolved field types, once per class (resolving them costs about
    0.7 ms, and every mapper and map run makes records)."""
    if cls not in _HINTS:
        _HINTS[cls] = typing.get_type_hints(cls)
    return _HINTS[cls]


@dataclass(frozen=True)
class Record:
    """Base of validated parameter sets (see the module docstring).

    Subclasses are frozen dataclasses; ``OWNER`` names them in messages. Construction
    coerces and checks every field, so an instance is always valid.
    """

    OWNER: ClassVar[str] = "parameters"

    def __post_init__(self) -> None:
        hints = _hints(type(self))
        for spec in dataclasses.fields(self):
            if not spec.init:
                continue  # derived in the subclass's __post_init__
            setting = f"{self.OWNER}.{spec.name}"  # what a command line names as a flag
            try:
                value = coerce(self.OWNER, spec.name, hints[spec.name], getattr(self, spec.name))
            except ParameterError as err:
                err.settings = err.settings or (setting,)
                raise
            rule = spec.metadata.get("rule")
            if value is not None and isinstance(rule, Rule) and not rule.check(value):
                shown = list(value) if isinstance(value, tuple) else value  # as YAML wrote it
                raise ParameterError(f"{self.OWNER}: {spec.name}={shown!r} out of range "
                                     f"({rule.rule})", setting=setting)
            object.__setattr__(self, spec.name, value)

    @classmethod
    def names(cls) -> tuple[str, ...]:
        """The parameter names, in declaration order."""
        return tuple(f.name for f in dataclasses.fields(cls))

    @classmethod
    def parse(cls, given: Mapping[str, object] | None = None) -> Self:
        """An instance from ``given`` (text or typed values); unknown names raise."""
        given = dict(given or {})
        unknown = sorted(set(given) - set(cls.names()))
        if unknown:
            raise ParameterError(f"{cls.OWNER}: unknown parameter(s) {', '.join(unknown)}; "
                                 f"valid: {', '.join(sorted(cls.names()))}")
        return cls(**given)

    # Any, not object: the mappers read their parameters from this dict as typed values.
    def as_dict(self) -> dict[str, Any]:
        """Parameters by name (JSON-ready scalars)."""
        return {name: getattr(self, name) for name in self.names()}

    def replace(self, **changes: object) -> Self:
        """A copy with ``changes`` applied (validated like a new record)."""
        return type(self).parse({**self.as_dict(), **changes})

    @classmethod
    def help(cls) -> dict[str, str]:
        """What each parameter means and its rule, for ``--help`` texts and docs."""
        out = {}
        hints = _hints(cls)
        for spec in dataclasses.fields(cls):
            rule = spec.metadata.get("rule")
            rule = rule if isinstance(rule, Rule) else Rule()
            said = rule.rule or _choices(hints[spec.name])
            out[spec.name] = f"{rule.help} ({said})" if said else rule.help
        return out


def _choices(kind: object) -> str:
    """``a|b|c`` for a Literal or enum type (optional or not), else ""."""
    options = [k for k in get_args(kind) if k is not type(None)] \
        if get_origin(kind) in (types.UnionType, typing.Union) else [kind]
    kind = options[0] if len(options) == 1 else kind
    if get_origin(kind) is Literal:
        return "|".join(map(str, get_args(kind)))
    if isinstance(kind, type) and issubclass(kind, enum.Enum):
        return "|".join(str(m.value) for m in kind)
    return ""


def key_values(items: Iterable[str]) -> dict[str, str]:
    """``["k=v", ...]`` -> ``{"k": "v"}`` (keys and values stripped, the value may hold
    '='): the one parser of settings given as text; an item without '=' or key raises
    ParameterError naming the item (a caller adds where it came from)."""
    out: dict[str, str] = {}
    for item in items:
        key, sep, value = item.partition("=")
        if not sep or not key.strip():
            raise ParameterError(f"{item!r}: expected KEY=VALUE")
        out[key.strip()] = value.strip()
    return out
