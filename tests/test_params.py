"""The one parameter mechanism (alte.params.Record): coercion, rules, unknown names."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

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
