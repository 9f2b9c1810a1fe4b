"""The mapper contract: the thesis' four and the documented example meet it; check_mapper
refuses each way a class can break it, naming the rule."""

from dataclasses import dataclass
from typing import ClassVar

import numpy as np
import pytest
from support.example import EXAMPLE, MeanGrid, NoisyGrid

from alte.errors import ContractError, MapperError
from alte.mappers import registry
from alte.mappers.api import API_VERSION, VARIANCE, Cells, MapperBase, Record, param
from alte.testing import check_mapper, scene


def test_builtins_meet_the_contract() -> None:
    for cls in registry.BUILTIN:
        check_mapper(cls)


def test_example_is_short_and_meets_the_contract() -> None:
    assert len(EXAMPLE.read_text().splitlines()) <= 50
    check_mapper(MeanGrid)
    check_mapper(NoisyGrid)
    mapper = MeanGrid(cell=2.0)
    for points, origin in scene():
        mapper.insert(points, origin)
    assert mapper.cost == 3000 and len(mapper.cells()) == 64  # 1..15 m: cells 0..7 squared


@dataclass(frozen=True)
class _Params(Record):
    OWNER: ClassVar[str] = "broken"
    cell: float = param(1.0, lambda v: v > 0, "cell > 0")


def _variant(**changes: object) -> type:
    """A subclass of the example with class attributes or methods replaced."""
    return type("Broken", (MeanGrid,), dict(changes))


def _wrong_cells(self: MapperBase[_Params]) -> Cells:
    cells = MeanGrid.cells(self)
    return Cells(cells.centers[:, :2], cells.sizes, cells.value, cells.occupied, cells.level)


def _no_layer(self: MapperBase[_Params]) -> Cells:
    return MeanGrid.cells(self)


def _negative_variance(self: MapperBase[_Params]) -> Cells:
    cells = MeanGrid.cells(self)
    return Cells(cells.centers, cells.sizes, cells.value, cells.occupied, cells.level,
                 {VARIANCE: np.full(len(cells), -1.0)})


def _untyped_error(self: MapperBase[_Params], points: object, origin: object) -> None:
    raise RuntimeError("boom")


def _accepts_anything(self: MapperBase[_Params], points: object, origin: object) -> None:
    return None


def _thick(self: MapperBase[_Params]) -> Cells:
    cells = MeanGrid.cells(self)
    sizes = cells.sizes.copy()
    sizes[:, 2] = 1.0
    return Cells(cells.centers, sizes, cells.value, cells.occupied, cells.level)


def _in_feet(self: MapperBase[_Params]) -> Cells:
    cells = MeanGrid.cells(self)
    return Cells(cells.centers * 30.0, cells.sizes, cells.value, cells.occupied, cells.level)


@pytest.mark.parametrize(("changes", "match"), [
    ({"api_version": API_VERSION + 1}, r"written against mapper contract version 2; this "
                                       r"alte implements version 1"),
    ({"name": "Mean Grid"}, r"name='Mean Grid' must be a lowercase identifier"),
    ({"title": ""}, r"title='' must be a non-empty str"),
    ({"dims": 4}, r"dims=4 must be 2 or 3"),
    ({"exports": frozenset({".bt"})}, r"exports=.* must be a frozenset of suffixes "
                                      r"including '\.npz'"),
    ({"view_params": frozenset({"kappa"})}, r"view_params \['kappa'\] are not parameters"),
    ({"settings_grid": {"cell": (0.0,)}}, r"settings_grid\['cell'\]: meangrid: cell=0\.0 "
                                          r"out of range"),
    ({"settings_grid": {"size": (1,)}}, r"settings_grid names 'size', not a parameter"),
    ({"Settings": dict}, r"Settings must be a alte\.params\.Record dataclass"),
    ({"cells": _wrong_cells}, r"cells\(\)\.centers is float64 \(\d+, 2\), expected"),
    ({"layers": frozenset({VARIANCE}), "cells": _no_layer},
     r"cells\(\)\.layers has \[\], the class declares layers=\['variance'\]"),
    ({"layers": frozenset({VARIANCE}), "cells": _negative_variance},
     r"the variance layer holds negative values"),
    ({"_insert": _untyped_error}, r"insert\(\) of the scene raised RuntimeError: boom"),
    ({"insert": _accepts_anything}, r"insert\(\) of NaN points was accepted"),
    ({"cells": _thick}, r"a 2D map's cells have sizes\[:, 2\] == 0"),
    ({"cells": _in_feet}, r"cell heights .* lie outside the scene's"),
])
def test_check_mapper_refuses(changes: dict[str, object], match: str) -> None:
    with pytest.raises(ContractError, match=match):
        check_mapper(_variant(**changes))


def test_check_mapper_lists_every_class_problem() -> None:
    broken = _variant(title=3, dims=1, cost_unit="points")
    with pytest.raises(ContractError, match=r"title=3 .*; dims=1 .*; cost_unit='points'"):
        check_mapper(broken)
    with pytest.raises(ContractError, match=r"is not a class"):
        check_mapper(MeanGrid(cell=1.0))


def test_a_class_without_the_methods() -> None:
    class Bare:
        api_version = API_VERSION
        name, title, dims = "bare", "Bare", 2

    with pytest.raises(ContractError, match=r"no class attribute incremental .*no method "
                                            r"insert\(\)"):
        check_mapper(Bare)


def test_reread_is_refused_for_stored_parameters() -> None:
    mapper = MeanGrid(cell=1.0)
    with pytest.raises(MapperError, match=r"meangrid: cell change\(s\) what the map stores"):
        mapper.reread(cell=2.0)
