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
from typing import ClassVar, Literal, get_args

from alte.errors import AlteError, ParameterError
from alte.mappers import DomainUse, Mapper
from alte.metrics.maps import MapPointSet
from alte.params import Record, param
from alte.sim.profile import PROFILES

__all__ = ["BASE", "DOMAINS", "POSES", "Variant", "parse_variants", "spec_error"]

#: The name of the grid as written (no change).
BASE = "base"
DomainName = Literal["auto", "control", "data"]
PosesName = Literal["recorded", "odometry"]
#: Valid ``domain`` values (those of :class:`alte.pipeline.DomainPolicy`).
DOMAINS: tuple[str, ...] = get_args(DomainName)
#: Valid ``poses`` values.
POSES: tuple[str, ...] = get_args(PosesName)


def _profile(value: str) -> bool:
    return value in PROFILES


@dataclass(frozen=True)
class Variant(Record):
    """One ablation: what it changes (module docstring) and a sentence saying so."""

    OWNER: ClassVar[str] = "variant"
    name: str = param(BASE, help="the variant's name")
    text: str = param("the grid as specified", help="what it changes, in words")
    domain: DomainName = param("auto", help="the maps' root cell")
    set_b: MapPointSet = param(MapPointSet.CORNERS, help="set B of HD/MHD")
    params: Mapping[str, Mapping[str, object]] = field(default_factory=dict)
    terrains: tuple[str, ...] = param((), help="the terrains it runs on (empty: the sweep's)")
    sensor: str = param("thesis", _profile, "|".join(PROFILES), "the simulated sensor")
    deskew: bool = param(True, help="deskew swept scans")
    poses: PosesName = param("recorded", help="recorded poses or the odometry's")

    def domain_for(self, mapper: type[Mapper]) -> str:
        """The domain policy a run of ``mapper`` gets (``auto`` where it uses none)."""
        return "auto" if mapper.domain_use is DomainUse.UNUSED else self.domain

    def set_b_for(self, mapper: type[Mapper]) -> MapPointSet:
        """The set B a run of ``mapper`` gets (``occupied`` is ``corners`` in 3D)."""
        return (MapPointSet.CORNERS if self.set_b is MapPointSet.OCCUPIED and mapper.dims == 3
                else self.set_b)

    def params_for(self, mapper: type[Mapper], row: Mapping[str, object]) -> dict[str, object]:
        """``row`` with this variant's parameter changes for ``mapper``."""
        return {**row, **self.params.get(mapper.name, {})}


def spec_error(source: str, key: str, message: str) -> ParameterError:
    """An error in a sweep spec, naming the spec and the key."""
    return ParameterError(f"{source}: {key}: {message}")


def _params(source: str, key: str, value: object, mappers: tuple[type[Mapper], ...]
            ) -> dict[str, dict[str, object]]:
    if not isinstance(value, Mapping):
        raise spec_error(source, key, f"{value!r} must map mapper names to parameter changes")
    out = {}
    ours = {cls.name: cls for cls in mappers}
    for mapper, changes in value.items():
        where = f"{key}.{mapper}"
        if mapper not in ours:
            raise spec_error(source, where, f"not a mapper of this sweep ({', '.join(ours)})")
        if not isinstance(changes, Mapping) or not changes:
            raise spec_error(source, where, f"{changes!r} must map parameter names to values")
        try:
            resolved = ours[mapper].Settings.parse({str(k): v for k, v in changes.items()}
                                                 ).as_dict()
        except AlteError as err:
            raise spec_error(source, where, str(err)) from err
        out[str(mapper)] = {str(k): resolved[str(k)] for k in changes}
    return out


def _variant(source: str, name: str, body: object, terrains: tuple[str, ...],
             mappers: tuple[type[Mapper], ...]) -> Variant:
    key = f"variants.{name}"
    if name == BASE:
        raise spec_error(source, key, f"{BASE!r} is the grid as written; name the variant "
                         "otherwise")
    if not isinstance(body, Mapping) or not body:
        raise spec_error(source, key, "must say what changes (domain, set_b and/or params)")
    if "name" in body:
        raise spec_error(source, key, "'name' is the variant's key, not a setting")
    own = body.get("terrains", list(terrains))
    own = [own] if isinstance(own, str) else own
    if not isinstance(own, list) or not own or set(own) - set(terrains):
        raise spec_error(source, f"{key}.terrains", f"{own!r} must be a non-empty list of "
                         "the sweep's terrains")
    given = {**body, "name": name, "text": str(body.get("text", "")),
             "terrains": tuple(dict.fromkeys(own)),
             "params": _params(source, f"{key}.params", body.get("params", {}), mappers)}
    try:
        variant = Variant.parse({str(k): v for k, v in given.items()})
    except ParameterError as err:
        raise spec_error(source, key, str(err)) from err
    if variant == Variant(name=variant.name, text=variant.text, terrains=variant.terrains):
        raise spec_error(source, key, "changes nothing (give domain, set_b, params, sensor or "
                         "poses)")
    return variant


def parse_variants(source: str, raw: object, terrains: tuple[str, ...],
                   mappers: tuple[type[Mapper], ...]) -> tuple[Variant, ...]:
    """The spec's ``variants`` mapping, validated (errors name the key)."""
    if raw is None:
        return ()
    if not isinstance(raw, Mapping):
        raise spec_error(source, "variants", f"{raw!r} must map variant names to their changes")
    return tuple(_variant(source, str(name), body, terrains, mappers)
                 for name, body in raw.items())
