"""Ablation variants of a sweep: the same grid with one thing changed.

A spec's ``variants`` maps a name to what it changes against the grid as written (the
``base`` variant): the map's root cell (``domain``: ``auto``, ``control`` or ``data``,
see :class:`alte.pipeline.DomainPolicy`), the definition of set B in HD/MHD (``set_b``,
see :data:`alte.metrics.maps.SET_B`), some mappers' parameters (``params``: mapper ->
{parameter: value}) or the simulated sensor (``sensor``: a profile of
:data:`alte.sim.profile.PROFILES`, its terrains simulated into ``NAME-PROFILE``; with
``deskew: false`` its swept scans are registered as taken) or where the poses come
from (``poses: odometry``: the whole mission is simulated and posed by the odometry
``auto`` picks, LiDAR-inertial when the bag has an IMU, and the sweep's ``frames`` are
then picked from it), optionally on fewer ``terrains``. A variant runs only the maps it
changes: a run whose effective settings equal a base run's (a mapper the variant does
not touch, or Octomap under another domain, which it does not use) *is* that run, once.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from alte.errors import AlteError, ParameterError
from alte.mappers import DomainUse, make_mapper, mapper_class
from alte.metrics.maps import SET_B, SetB
from alte.pipeline import DomainPolicy
from alte.sim.profile import PROFILES

__all__ = ["BASE", "DOMAINS", "POSES", "Variant", "parse_variants"]

#: The name of the grid as written (no change).
BASE = "base"
#: Valid ``domain`` values.
DOMAINS = tuple(p.value for p in DomainPolicy)
_KEYS = ("text", "domain", "set_b", "params", "terrains", "sensor", "deskew", "poses")
#: Valid ``poses`` values.
POSES = ("recorded", "odometry")


@dataclass(frozen=True)
class Variant:
    """One ablation: what it changes (module docstring) and a sentence saying so."""

    name: str = BASE
    text: str = "the grid as specified"
    domain: str = DomainPolicy.AUTO.value
    set_b: SetB = SetB.CORNERS
    params: Mapping[str, Mapping[str, Any]] = field(default_factory=dict)
    terrains: tuple[str, ...] = ()
    sensor: str = "thesis"
    deskew: bool = True
    poses: str = "recorded"

    def domain_for(self, mapper: str) -> str:
        """The domain policy a run of ``mapper`` gets (``auto`` where it uses none)."""
        return (DomainPolicy.AUTO.value if mapper_class(mapper).domain_use is DomainUse.UNUSED
                else self.domain)

    def set_b_for(self, mapper: str) -> SetB:
        """The set B a run of ``mapper`` gets (``occupied`` is ``corners`` in 3D)."""
        return (SetB.CORNERS if self.set_b is SetB.OCCUPIED and mapper_class(mapper).dims == 3
                else self.set_b)

    def params_for(self, mapper: str, row: Mapping[str, Any]) -> dict[str, Any]:
        """``row`` with this variant's parameter changes for ``mapper``."""
        return {**row, **self.params.get(mapper, {})}


def _fail(source: str, key: str, message: str) -> ParameterError:
    return ParameterError(f"{source}: {key}: {message}")


def _choice(source: str, key: str, value: Any, valid: tuple[str, ...]) -> str:
    if value not in valid:
        raise _fail(source, key, f"{value!r}: expected one of {', '.join(valid)}")
    return str(value)


def _flag(source: str, key: str, value: Any) -> bool:
    if not isinstance(value, bool):
        raise _fail(source, key, f"{value!r}: expected true or false")
    return value


def _params(source: str, key: str, value: Any, mappers: tuple[str, ...]
            ) -> dict[str, dict[str, Any]]:
    if not isinstance(value, Mapping):
        raise _fail(source, key, f"{value!r} must map mapper names to parameter changes")
    out = {}
    for mapper, changes in value.items():
        where = f"{key}.{mapper}"
        if mapper not in mappers:
            raise _fail(source, where, f"not a mapper of this sweep ({', '.join(mappers)})")
        if not isinstance(changes, Mapping) or not changes:
            raise _fail(source, where, f"{changes!r} must map parameter names to values")
        try:
            resolved = make_mapper(str(mapper), dict(changes)).params.as_dict()
        except AlteError as err:
            raise _fail(source, where, str(err)) from err
        out[str(mapper)] = {str(k): resolved[str(k)] for k in changes}
    return out


def _variant(source: str, name: str, body: Any, terrains: tuple[str, ...],
             mappers: tuple[str, ...]) -> Variant:
    key = f"variants.{name}"
    if name == BASE:
        raise _fail(source, key, f"{BASE!r} is the grid as written; name the variant otherwise")
    if not isinstance(body, Mapping) or not body:
        raise _fail(source, key, "must say what changes (domain, set_b and/or params)")
    unknown = sorted(set(map(str, body)) - set(_KEYS))
    if unknown:
        raise _fail(source, key, f"unknown key(s) {', '.join(unknown)}; valid: {', '.join(_KEYS)}")
    own = body.get("terrains", list(terrains))
    own = [own] if isinstance(own, str) else own
    if not isinstance(own, list) or not own or set(own) - set(terrains):
        raise _fail(source, f"{key}.terrains", f"{own!r} must be a non-empty list of the "
                    "sweep's terrains")
    variant = Variant(
        name, str(body.get("text", "")),
        _choice(source, f"{key}.domain", body.get("domain", "auto"), DOMAINS),
        SetB(_choice(source, f"{key}.set_b", body.get("set_b", "corners"), SET_B)),
        _params(source, f"{key}.params", body.get("params", {}), mappers),
        tuple(dict.fromkeys(own)),
        _choice(source, f"{key}.sensor", body.get("sensor", "thesis"), tuple(PROFILES)),
        _flag(source, f"{key}.deskew", body.get("deskew", True)),
        _choice(source, f"{key}.poses", body.get("poses", "recorded"), POSES))
    if variant == Variant(variant.name, variant.text, terrains=variant.terrains):
        raise _fail(source, key, "changes nothing (give domain, set_b, params, sensor or poses)")
    return variant


def parse_variants(source: str, raw: Any, terrains: tuple[str, ...],
                   mappers: tuple[str, ...]) -> tuple[Variant, ...]:
    """The spec's ``variants`` mapping, validated (errors name the key)."""
    if raw is None:
        return ()
    if not isinstance(raw, Mapping):
        raise _fail(source, "variants", f"{raw!r} must map variant names to their changes")
    return tuple(_variant(source, str(name), body, terrains, mappers)
                 for name, body in raw.items())
