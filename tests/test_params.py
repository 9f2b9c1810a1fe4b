"""The one parameter mechanism (alte.params.Record): coercion, rules, unknown names."""

from __future__ import annotations

import enum
from dataclasses import dataclass
from pathlib import Path
from typing import ClassVar, Literal

import pytest

from alte.errors import ParameterError
from alte.params import Record, param


@dataclass(frozen=True)
class Sample(Record):
    OWNER: ClassVar[str] = "alte2d"
    kappa: float = param(0.1, lambda v: v >= 0, ">= 0", "threshold")
    max_res: int = param(6, lambda v: 1 <= v <= 20, "1..20")
    variant: str = param("cube", lambda v: v in {"cube", "fixed"}, "cube|fixed")
    prune: bool = param(True)
    limit: float | None = param(None, lambda v: v > 0, "> 0")


def test_defaults_and_coercion_from_strings():
    out = Sample.parse({"kappa": "0.5", "max_res": "4", "prune": "no", "limit": "none"})
    assert out.as_dict() == {"kappa": 0.5, "max_res": 4, "variant": "cube", "prune": False,
                             "limit": None}
    assert Sample.parse({"max_res": 3.0}).max_res == 3
    assert Sample.parse({"limit": "2"}).limit == 2.0


def test_unknown_key_lists_valid_ones():
    with pytest.raises(ParameterError, match=r"alte2d: unknown parameter\(s\) kapa; "
                                             r"valid: kappa, limit, max_res, prune, variant"):
        Sample.parse({"kapa": 1})


@pytest.mark.parametrize(("given", "pattern"), [
    ({"kappa": -1.0}, r"kappa=-1\.0 out of range \(>= 0\)"),
    ({"max_res": 0}, r"max_res=0 out of range \(1\.\.20\)"),
    ({"max_res": 2.5}, r"max_res=2\.5 must be an integer"),
    ({"max_res": "1.5"}, r"max_res='1\.5' must be an integer"),
    ({"max_res": "inf"}, r"max_res='inf' must be an integer"),
    ({"max_res": "two"}, r"max_res='two' is not a valid int"),
    ({"max_res": True}, r"max_res=True is not a valid int"),
    ({"kappa": "nan"}, r"kappa=nan must be finite"),
    ({"kappa": [1]}, r"kappa=\[1\] is not a valid float"),
    ({"prune": "maybe"}, r"prune='maybe' is not a boolean"),
    ({"variant": "sphere"}, r"variant='sphere' out of range \(cube\|fixed\)"),
    ({"variant": 3.5j}, r"variant=3\.5j is not a valid str"),
    ({"limit": -1}, r"limit=-1\.0 out of range \(> 0\)"),
])
def test_out_of_range_values(given, pattern):
    with pytest.raises(ParameterError, match=pattern):
        Sample.parse(given)


def test_records_are_frozen_and_replace_revalidates():
    rec = Sample()
    with pytest.raises(AttributeError):
        rec.kappa = 1.0  # type: ignore[misc]
    assert rec.replace(kappa="2").kappa == 2.0
    with pytest.raises(ParameterError, match=r"kappa=-2\.0 out of range"):
        rec.replace(kappa=-2)


def test_help_names_rules():
    assert Sample.help()["kappa"] == "threshold (>= 0)"


class Colour(enum.Enum):
    RED = "red"
    BLUE = "blue"


@dataclass(frozen=True)
class Outer(Record):
    """A record with the structured kinds a spec holds: an enum, tuples, a path and a
    nested record, each coerced from what YAML or a command line gives."""

    OWNER: ClassVar[str] = "outer"
    colour: Colour = param(Colour.RED, help="a colour")
    shape: Literal["cube", "ball"] = param("cube", help="a shape")
    seeds: tuple[int, ...] = param((0,), lambda v: len(v) > 0, "not empty")
    at: tuple[float, float] = param((0.0, 0.0))
    where: Path | None = param(None)
    inner: Sample = param(Sample())


def test_structured_kinds_are_coerced_from_yaml_values():
    out = Outer.parse({"colour": "blue", "seeds": ["3", 4.0], "at": [1, "2.5"],
                       "where": "a/b", "inner": {"kappa": "0.5"}})
    assert out == Outer(Colour.BLUE, "cube", (3, 4), (1.0, 2.5), Path("a/b"), Sample(kappa=0.5))
    assert Outer.parse({"inner": Sample(max_res=3)}).inner.max_res == 3
    assert Outer.help()["colour"] == "a colour (red|blue)"
    assert Outer.help()["shape"] == "a shape (cube|ball)"


@pytest.mark.parametrize(("given", "pattern"), [
    ({"colour": "green"}, r"outer: colour='green' out of range \(red\|blue\)"),
    ({"shape": "cone"}, r"outer: shape='cone' out of range \(cube\|ball\)"),
    ({"seeds": []}, r"outer: seeds=\[\] out of range \(not empty\)"),
    ({"seeds": "3"}, r"outer: seeds='3' is not a list"),
    ({"seeds": [1, "x"]}, r"outer: seeds\[1\]='x' is not a valid int"),
    ({"at": [1.0]}, r"outer: at=\[1\.0\]: expected 2 values"),
    ({"where": 3}, r"outer: where=3 is not a path"),
    ({"inner": 3}, r"outer: inner=3 must be a mapping of alte2d parameters"),
    ({"inner": {"kappa": -1}}, r"outer: inner: alte2d: kappa=-1\.0 out of range \(>= 0\)"),
])
def test_structured_kinds_name_the_field_in_errors(given, pattern):
    with pytest.raises(ParameterError, match=pattern):
        Outer.parse(given)


def test_key_values_is_the_one_settings_parser() -> None:
    from alte.params import key_values

    assert key_values([" a = 1 ", "b=x=y", "c="]) == {"a": "1", "b": "x=y", "c": ""}
    with pytest.raises(ParameterError, match=r"^'a': expected KEY=VALUE$"):
        key_values(["a"])
    with pytest.raises(ParameterError, match=r"^' =2': expected KEY=VALUE$"):
        key_values([" =2"])
