"""The sweep's per-run work: runs sharing a map (one feed, re-read per run, measured against a
prepared reference) give the rows of today's path, one fresh map per run measured from
scratch (``alte.lab.studies.experiments.measure``: pipeline run + ``measure_map`` with no
reference), value for value."""

from __future__ import annotations

import math
import random

import pandas as pd
import pytest

from alte.lab.studies.experiments import measure
from alte.lab.studies.sweep import TIMING_COLUMNS, parse_spec, plan_runs, run_sweep
from alte.lab.studies.sweep.groups import _dataset, group_runs, map_key, run_group, run_one
from alte.metrics import freespace as freespace_module
from alte.pipeline import DomainPolicy, MapSettings
from alte.sim import ensure_terrain, terrain_folder

RAW = {
    "terrains": ["sim_lan_2", "sim_nav_1"], "frames": 3, "seeds": [0],
    "truth": {"n_samples": 1500, "grid_step": 0.5},
    "mappers": {
        "quadtree": {"grid": {"max_points": [20, 300]}},
        "alte2d": {"grid": {"kappa": [0.01, 1.0], "max_res": [5, 7], "min_pts": [10, 100]}},
        "octomap": {"grid": {"resolution": [1.0, 2.5]}},
        "alte3d": {"grid": {"max_res": [5, 7], "min_pts_split": [5, 40], "min_pts": [5, 40]}},
    },
    "variants": {
        "domain_data": {"domain": "data", "terrains": ["sim_nav_1"]},
        "set_b_centers": {"set_b": "centers"},
        "set_b_occupied": {"set_b": "occupied", "terrains": ["sim_lan_2"]},
        "occupancy_max": {"params": {"quadtree": {"occupancy": "max"}}},
        "per_leaf": {"params": {"alte3d": {"occupancy_level": 0}}},
    },
}


@pytest.fixture(scope="module")
def spec(tmp_path_factory):
    data = tmp_path_factory.mktemp("data")
    return parse_spec({**RAW, "data_dir": str(data), "output": str(data / "runs")}, "work")


def _slow_row(run, data_dir: str) -> dict:
    """Today's path: a fresh map for the run alone, every metric computed from scratch."""
    data = _dataset(run.input_key(), data_dir)
    spec = MapSettings(run.mapper, dict(run.params), domain=DomainPolicy(run.domain))
    return measure(data, run.mapper, truth=run.truth, spec=spec, set_b=run.set_b).metrics.flat()


def _same(a: object, b: object) -> bool:
    if isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
        return True
    return a == b


def test_groups_share_a_map_only_where_view_parameters_or_set_b_differ(spec):
    runs = plan_runs(spec)
    groups = group_runs(runs)
    assert sum(len(g) for g in groups) == len(runs)
    assert sorted(r.run_id for g in groups for r in g.runs) == sorted(r.run_id for r in runs)
    sizes = {g.runs[0].mapper: [] for g in groups}
    for g in groups:
        sizes[g.runs[0].mapper].append(len(g))
        assert len({map_key(r) for r in g.runs}) == 1
        assert len({(r.terrain, r.seed, r.domain) for r in g.runs}) == 1
    # 3D-ALTE: per max_res and domain, 2 x 2 settings x (corners, centers, per-leaf rule)
    assert sorted(set(sizes["alte3d"])) == [4, 12]
    assert set(sizes["octomap"]) == {2}  # corners and centers of one resolution
    assert len(groups) < len(runs) / 4


def _groups_holding(runs: list, sample: list) -> list:
    """The map groups of ``runs`` that hold a run of ``sample``, whole (each shares its
    feed among all its runs): only those rows are compared."""
    wanted = {run.run_id for run in sample}
    return [g for g in group_runs(runs) if any(r.run_id in wanted for r in g.runs)]


def test_grouped_rows_equal_fresh_maps_measured_from_scratch(spec, monkeypatch):
    # few free leaves drawn, so Octomap's and 3D-ALTE's free-space truth takes the
    # drawing path on these short missions too
    monkeypatch.setattr(freespace_module, "FREE_SPACE_CELLS", 300)
    data_dir = spec.data_dir
    runs = plan_runs(spec)
    for terrain in spec.terrains:
        ensure_terrain(terrain, data_dir, 0, spec.frames)
    sample = random.Random(0).sample(runs, 40)
    rows = {}
    for group in _groups_holding(runs, sample):
        members = list(group.runs)
        random.Random(len(members)).shuffle(members)  # any order gives the same rows
        for run_id, row, err in run_group(type(group)(tuple(members)), data_dir):
            assert err is None, err
            rows[run_id] = row
    checked = 0
    for run in sample:
        slow = _slow_row(run, data_dir)
        fast = rows[run.run_id]
        for key, value in slow.items():
            if key in TIMING_COLUMNS or key == "time_repeats":
                continue
            assert _same(fast[key], value), (run.mapper, dict(run.params), run.set_b, key,
                                             fast[key], value)
            checked += 1
    assert checked > 40 * 20
    assert terrain_folder(data_dir, "sim_nav_1", spec.frames, 0).is_dir()


def test_run_one_is_a_group_of_one_and_raises_what_the_run_raised(spec, monkeypatch):
    run = next(r for r in plan_runs(spec) if r.mapper == "quadtree")
    row = run_one(run, spec.data_dir)
    assert row["run_id"] == run.run_id and row["cpu_s"] > 0 and row["wall_s"] > 0
    from alte.lab.studies.sweep import groups

    def broken(*args, **kwargs):
        raise MemoryError("no room")

    monkeypatch.setattr(groups, "timed_run", broken)
    with pytest.raises(MemoryError, match="no room"):
        run_one(run, spec.data_dir)


def test_a_run_failing_alone_leaves_its_group_going(spec, tmp_path, monkeypatch):
    from alte.lab.studies.sweep import groups

    real = groups.measure_map

    def picky(mapper, cloud, **kw):
        if kw["set_b"] == "centers":
            raise ValueError("not today")
        return real(mapper, cloud, **kw)

    monkeypatch.setattr(groups, "measure_map", picky)
    small = parse_spec({**RAW, "terrains": ["sim_lan_2"],
                        "mappers": {"quadtree": {"grid": {"max_points": [300]}}},
                        "variants": {"c": {"set_b": "centers"}},
                        "data_dir": spec.data_dir, "output": str(tmp_path)}, "one")
    result = run_sweep(small, scheduler="serial", progress=False)
    assert result.ran == 1 and [m for _, m in result.failed] == ["ValueError: not today"]
    table = pd.read_parquet(next(tmp_path.glob("run-*.parquet")))
    assert table["set_b"].tolist() == ["corners"]


def test_the_groups_of_one_input_build_and_read_it_once_per_process(spec, monkeypatch):
    """Every map group of an input takes it from the process's memo: the terrain is not
    built again nor its registration read again from the cache per group."""
    from alte.lab.studies.sweep import groups

    calls = []
    real = groups._registered

    def counted(key, data_dir):
        calls.append(key)
        return real(key, data_dir)

    monkeypatch.setattr(groups, "_registered", counted)
    groups._dataset.cache_clear()
    groups._reference.cache_clear()
    mine = [g for g in group_runs(plan_runs(spec)) if g.runs[0].terrain == "sim_lan_2"
            and g.runs[0].domain == "auto"][:4]
    assert len(mine) == 4 and len({g.runs[0].input_key() for g in mine}) == 1
    for group in mine:
        assert all(err is None for _, _, err in run_group(group, spec.data_dir))
    assert calls == [mine[0].runs[0].input_key()]
    groups._dataset.cache_clear()
    groups._reference.cache_clear()
