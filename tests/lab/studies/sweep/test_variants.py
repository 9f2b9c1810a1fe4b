"""alte.lab.studies.sweep variants and seeds: parsing, shared runs, per-variant tables."""

from __future__ import annotations

import pandas as pd
import pytest

from alte.errors import ParameterError
from alte.lab.studies.sweep import (
    BASE,
    Variant,
    parse_spec,
    plan_runs,
    plan_variants,
    run_sweep,
    variant_table,
)
from alte.mappers import Alte2D, Alte3D, Octomap, Quadtree
from alte.metrics.maps import MapPointSet


def _raw(**changes):
    raw = {"terrains": ["sim_lan_1", "sim_nav_1"], "frames": 4, "seeds": [0, 1],
           "truth": {"n_samples": 2000},
           "mappers": {"quadtree": {"rows": [{"max_points": 100}, {"max_points": 400}]},
                       "octomap": {"rows": [{"resolution": 1.0}]},
                       "alte3d": {"rows": [{"max_res": 4}]}}}
    return raw | changes


def test_seeds_multiply_the_grid_seed_first():
    runs = plan_runs(parse_spec(_raw()))
    assert len(runs) == 2 * 2 * 4
    assert [r.seed for r in runs] == [0] * 8 + [1] * 8
    assert [r.terrain for r in runs[:8]] == ["sim_lan_1"] * 4 + ["sim_nav_1"] * 4
    assert len({r.run_id for r in runs}) == 16


def test_old_single_seed_runs_keep_their_ids():
    one = plan_runs(parse_spec(_raw(seeds=[1])))
    assert {r.run_id for r in one} == {r.run_id for r in plan_runs(parse_spec(
        {k: v for k, v in _raw(seed=1).items() if k != "seeds"}))}
    assert all("domain" not in r.key() and "set_b" not in r.key() for r in one)


def test_variants_run_only_what_they_change():
    raw = _raw(seeds=[0], variants={
        "data": {"domain": "data", "text": "root over the data"},
        "centres": {"set_b": "centers", "terrains": ["sim_nav_1"]},
        "occupied": {"set_b": "occupied"},
        "max": {"params": {"quadtree": {"occupancy": "max"}}}})
    spec = parse_spec(raw)
    assert [v.name for v in spec.variants] == ["data", "centres", "occupied", "max"]
    assert spec.variants[0].text == "root over the data"
    pairs = plan_variants(spec)
    names = [n for n, _ in pairs]
    assert names.count(BASE) == 8 and names.count("data") == 8 and names.count("centres") == 4
    runs = plan_runs(spec)
    base = {r.run_id for n, r in pairs if n == BASE}
    own = {n: {r.run_id for m, r in pairs if m == n} - base for n in ("data", "centres",
                                                                       "occupied", "max")}
    # Octomap uses no domain: its runs are the base ones; the others are re-run.
    assert {r.mapper for r in runs if r.run_id in own["data"]} == {"quadtree", "alte3d"}
    assert all(r.domain == "auto" for n, r in pairs if n == "data" and r.mapper == "octomap")
    assert len(own["centres"]) == 4  # every mapper on sim_nav_1
    # set B "occupied" is "corners" for 3D maps: only the 2D maps are re-run
    assert {r.mapper for r in runs if r.run_id in own["occupied"]} == {"quadtree"}
    assert {r.mapper for r in runs if r.run_id in own["max"]} == {"quadtree"}
    assert next(dict(r.params) for r in runs if r.run_id in own["max"]) == {
        "max_points": 100, "occupancy": "max"}
    assert len(runs) == 8 + sum(map(len, own.values()))


def test_variant_helpers():
    v = Variant("v", domain="data", set_b=MapPointSet.OCCUPIED, params={"alte2d": {"kappa": 2.0}})
    assert v.domain_for(Octomap) == "auto" and v.domain_for(Alte2D) == "data"
    assert v.set_b_for(Alte3D) is MapPointSet.CORNERS
    assert v.set_b_for(Quadtree) is MapPointSet.OCCUPIED
    assert v.params_for(Alte2D, {"kappa": 1.0, "max_res": 3}) == {"kappa": 2.0, "max_res": 3}
    assert v.params_for(Quadtree, {"max_points": 9}) == {"max_points": 9}


@pytest.mark.parametrize(("variants", "match"), [
    ([1], "variants: .* must map variant names"),
    ({"base": {"domain": "data"}}, "variants.base: 'base' is the grid as written"),
    ({"v": {}}, "variants.v: must say what changes"),
    ({"v": {"colour": 1}}, r"variants.v: variant: unknown parameter\(s\) colour"),
    ({"v": {"text": "nothing"}}, "variants.v: changes nothing"),
    ({"v": {"domain": "moon"}},
     r"variants.v: variant: domain='moon' out of range \(auto\|control\|data\)"),
    ({"v": {"set_b": "edges"}}, r"variants.v: variant: set_b='edges' out of range \(corners"),
    ({"v": {"params": [1]}}, "variants.v.params: .* must map mapper names"),
    ({"v": {"params": {"alte2d": {"kappa": 1}}}}, "variants.v.params.alte2d: not a mapper of"),
    ({"v": {"params": {"quadtree": {}}}}, "variants.v.params.quadtree: .* must map parameter"),
    ({"v": {"params": {"quadtree": {"occupancy": "mode"}}}},
     "variants.v.params.quadtree: .*occupancy"),
    ({"v": {"set_b": "centers", "terrains": ["exp_lan_1"]}},
     "variants.v.terrains: .* the sweep's terrains"),
    ({"v": {"set_b": "centers", "terrains": []}}, "variants.v.terrains: .* non-empty list"),
    ({"v": {"sensor": "lidar"}}, r"variants.v: variant: sensor='lidar' out of range \(thesis\|uav"),
    ({"v": {"sensor": "uav", "deskew": "maybe"}},
     r"variants.v: variant: deskew='maybe' is not a boolean"),
    ({"v": {"name": "w", "set_b": "centers"}}, r"variants.v: 'name' is the variant's key"),
    ({"v": {"sensor": "thesis"}}, "variants.v: changes nothing"),
    ({"v": {"poses": "lio"}},
     r"variants.v: variant: poses='lio' out of range \(recorded\|odometry\)"),
    ({"v": {"poses": "recorded"}}, "variants.v: changes nothing"),
])
def test_bad_variants_name_the_key(variants, match):
    with pytest.raises(ParameterError, match=match):
        parse_spec(_raw(variants=variants), "bad.yaml")


def test_variant_table_repeats_shared_runs_per_variant(tmp_path):
    raw = {"terrains": ["sim_lan_1"], "frames": 4, "seeds": [0, 1],
           "truth": {"n_samples": 2000}, "data_dir": str(tmp_path / "data"),
           "mappers": {"quadtree": {"rows": [{"max_points": 100}]},
                       "alte2d": {"rows": [{"kappa": 0.1, "max_res": 3}]}},
           "variants": {"occupied": {"set_b": "occupied"},
                        "max": {"params": {"quadtree": {"occupancy": "max"}}}}}
    spec = parse_spec(raw, "v.yaml")
    result = run_sweep(spec, scheduler="serial", output=tmp_path / "runs", progress=False)
    assert result.ran == 4 + 4 + 2 and not result.failed
    table = variant_table(spec, result.table)
    assert list(table.columns[:2]) == ["run_id", "variant"]
    counts = table.groupby(["variant", "mapper"]).size().to_dict()
    assert counts == {(n, m): 2 for n in (BASE, "occupied", "max")
                      for m in ("quadtree", "alte2d")}
    base = table[table["variant"] == BASE].set_index(["mapper", "seed"])
    occ = table[table["variant"] == "occupied"].set_index(["mapper", "seed"])
    high = table[table["variant"] == "max"].set_index(["mapper", "seed"])
    assert (occ["set_b"] == "occupied").all() and (base["set_b"] == "corners").all()
    # the occupancy rule moves nothing under the thesis' set B (every known leaf)...
    pd.testing.assert_series_equal(high.loc["quadtree", "mhd_m"], base.loc["quadtree", "mhd_m"])
    # ...while set B of the occupied leaves only moves Quadtree's MHD, not 2D-ALTE's
    assert (occ.loc["quadtree", "mhd_m"] != base.loc["quadtree", "mhd_m"]).all()
    pd.testing.assert_series_equal(occ.loc["alte2d", "mhd_m"], base.loc["alte2d", "mhd_m"])
    assert variant_table(spec, result.table.iloc[:0]).empty


def test_a_sensor_variant_reruns_every_map_on_that_sensor():
    spec = parse_spec(_raw(variants={"uav": {"sensor": "uav", "terrains": ["sim_nav_1"]},
                                     "raw": {"sensor": "uav", "deskew": False,
                                             "terrains": ["sim_nav_1"]}}))
    pairs = plan_variants(spec)
    base = {r.run_id for n, r in pairs if n == "base"}
    for name, deskew in (("uav", True), ("raw", False)):
        mine = [r for n, r in pairs if n == name]
        assert len(mine) == 2 * 4  # two seeds x the four maps of sim_nav_1
        assert all(r.sensor == "uav" and r.deskew is deskew for r in mine)
        assert not base & {r.run_id for r in mine}


def test_an_odometry_variant_poses_the_whole_mission_then_keeps_the_sweeps_scans():
    """``poses: odometry`` changes the runs' input (the whole mission simulated and posed by
    the odometry ``auto`` picks, :func:`alte.lab.studies.experiments.terrain`), not the rest."""
    spec = parse_spec(_raw(variants={"lio": {"sensor": "uav", "poses": "odometry",
                                             "terrains": ["sim_nav_1"]}}))
    pairs = plan_variants(spec)
    base = [r for n, r in pairs if n == "base" and r.terrain == "sim_nav_1"]
    mine = [r for n, r in pairs if n == "lio"]
    assert len(mine) == 2 * 4 and not {r.run_id for r in base} & {r.run_id for r in mine}
    run = mine[0]
    assert run.poses == "odometry" and run.key()["poses"] == "odometry"
    assert "poses" not in base[0].key() and base[0].poses == "recorded"
    assert run.input_key() == ("sim_nav_1", 4, 0, None, "uav", True, "odometry")
    assert base[0].input_key() == ("sim_nav_1", 4, 0, None, "thesis", True, "recorded")


def test_a_variants_set_b_is_a_typed_choice():
    spec = parse_spec(_raw(variants={"c": {"set_b": "centers"}}))
    assert spec.variants[0].set_b is MapPointSet.CENTERS
    runs = [r for n, r in plan_variants(spec) if n == "c"]
    assert runs
    assert all(r.set_b is MapPointSet.CENTERS and r.key()["set_b"] == "centers" for r in runs)


def test_inputs_posed_by_odometry_are_made_first():
    """The tradeoff grid's inputs: the whole missions posed by LIO (uav_lio) come first,
    so the two workers do not end on one long alignment; the rest keep their key order."""
    from alte.lab.studies.sweep.runner import input_order
    from alte.lab.studies.sweep.runs import plan_runs
    from alte.lab.studies.sweep.spec import load_spec
    from alte.paths import REPO_ROOT

    spec = load_spec(REPO_ROOT / "notebooks" / "sweeps" / "tradeoff.yaml")
    keys = sorted({r.input_key() for r in plan_runs(spec)}, key=input_order)
    posed = [k for k in keys if k[-1] == "odometry"]
    assert len(posed) == 6 and keys[:6] == posed
    assert keys[6:] == sorted(keys[6:], key=str)
