"""Plugin mappers in sweeps: added with their own settings grid, or listed by name."""

from __future__ import annotations

from collections.abc import Iterator

import pytest
from support.example import EXAMPLE

from alte.errors import ParameterError
from alte.lab.studies.sweep import override, parse_spec, plan_runs
from alte.lab.studies.sweep.groups import map_key
from alte.mappers import registry

RAW = {"terrains": ["sim_lan_1", "sim_nav_1"], "frames": 4,
       "mappers": {"quadtree": {"rows": [{"max_points": 100}]}}}


@pytest.fixture
def meangrid(monkeypatch: pytest.MonkeyPatch) -> Iterator[None]:
    """The how-to's example registered through ALTE_MAPPERS."""
    monkeypatch.syspath_prepend(str(EXAMPLE.parent))
    monkeypatch.setenv(registry.ENV, "mean_grid:MeanGrid")
    registry.refresh()
    yield
    registry.refresh()


def test_plugins_join_with_their_settings_grid(meangrid: None) -> None:
    base = parse_spec(RAW, "s.yaml")
    assert [g.mapper for g in base.mappers] == ["quadtree"]
    spec = override(base, plugins=True)
    assert spec.settings.plugins and [g.mapper for g in spec.mappers][:1] == ["quadtree"]
    grid = next(g for g in spec.mappers if g.mapper == "meangrid")
    assert grid.rows == tuple({"cell": c} for c in (0.25, 0.5, 1.0, 2.0))
    assert grid.terrains == ("sim_lan_1", "sim_nav_1")
    runs = [r for r in plan_runs(spec) if r.mapper == "meangrid"]
    assert len(runs) == 8 and runs[0].cls.title == "Mean grid"
    assert len({map_key(r) for r in runs}) == 8
    assert [g.mapper for g in parse_spec({**RAW, "plugins": True}, "s.yaml").mappers] == [
        g.mapper for g in spec.mappers]


def test_a_plugin_listed_by_name_keeps_the_spec_rows(meangrid: None) -> None:
    raw = {**RAW, "plugins": True,
           "mappers": {**RAW["mappers"], "meangrid": {"grid": {"cell": ["0.75"]}}},
           "variants": {"coarse": {"params": {"meangrid": {"cell": 3}}}}}
    spec = parse_spec(raw, "s.yaml")
    (grid,) = [g for g in spec.mappers if g.mapper == "meangrid"]
    assert grid.rows == ({"cell": 0.75},)
    coarse = [r for r in plan_runs(spec) if r.mapper == "meangrid" and r.params["cell"] == 3.0]
    assert len(coarse) == 2
    with pytest.raises(ParameterError, match=r"s\.yaml: mappers\.meangrid: meangrid: cell=0\.0 out "
                                         r"of range \(cell > 0\)"):
        parse_spec({**raw, "mappers": {"meangrid": {"rows": [{"cell": 0}]}}}, "s.yaml")
