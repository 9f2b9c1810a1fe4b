import numpy as np
import pytest

from alte.errors import MapperError, ParameterError
from alte.mappers.base import Param, check_points, parse_params

SPECS = {
    "kappa": Param(float, 0.1, lambda v: v >= 0, ">= 0"),
    "max_res": Param(int, 6, lambda v: 1 <= v <= 20, "1..20"),
    "variant": Param(str, "cube", lambda v: v in {"cube", "fixed"}, "cube|fixed"),
    "prune": Param(bool, True),
}


def test_defaults_and_coercion_from_strings():
    out = parse_params("alte2d", SPECS, {"kappa": "0.5", "max_res": "4", "prune": "no"})
    assert out == {"kappa": 0.5, "max_res": 4, "variant": "cube", "prune": False}


def test_unknown_key_lists_valid_ones():
    with pytest.raises(ParameterError, match=r"unknown parameter\(s\) kapa; valid: kappa, max_res"):
        parse_params("alte2d", SPECS, {"kapa": 1})


@pytest.mark.parametrize(("given", "pattern"), [
    ({"kappa": -1.0}, r"kappa=-1\.0 out of range \(>= 0\)"),
    ({"max_res": 0}, r"max_res=0 out of range \(1\.\.20\)"),
    ({"max_res": 2.5}, r"max_res=2\.5 must be an integer"),
    ({"max_res": "1.5"}, r"max_res='1\.5' must be an integer"),
    ({"max_res": "inf"}, r"max_res='inf' must be an integer"),
    ({"max_res": "two"}, r"max_res='two' is not a valid int"),
    ({"kappa": "nan"}, r"kappa=nan must be finite"),
    ({"prune": "maybe"}, r"prune='maybe' is not a boolean"),
    ({"variant": "sphere"}, r"variant='sphere' out of range"),
])
def test_out_of_range_values(given, pattern):
    with pytest.raises(ParameterError, match=pattern):
        parse_params("alte2d", SPECS, given)


def test_check_points():
    pts = check_points([[0, 0, 0], [1, 2, 3]], "quadtree")
    assert pts.dtype == np.float64
    with pytest.raises(MapperError, match=r"quadtree: points must have shape \(N, 3\)"):
        check_points(np.zeros((3, 2)), "quadtree")
    with pytest.raises(MapperError, match="NaN or inf"):
        check_points([[0, np.nan, 0]], "quadtree")
