"""alte.lab.studies.sweep: spec validation, run ids, Parquet store, serial/Dask runs, analysis."""

from __future__ import annotations

import pandas as pd
import pytest

import alte.sim
from alte.errors import AlteError, ParameterError
from alte.lab.studies.sweep import (
    TIMING_COLUMNS,
    SweepSettings,
    finished_ids,
    load_results,
    load_spec,
    main_effects,
    override,
    parse_spec,
    plan_runs,
    run_sweep,
    sensitivity_ranking,
    sensitivity_table,
    write_row,
)
from alte.lab.studies.sweep import groups as sweep_groups
from alte.lab.studies.sweep import runner as sweep_runner


def _raw(**changes):
    raw = {"terrains": ["sim_lan_1"], "frames": 4, "truth": {"n_samples": 2000},
           "mappers": {"alte2d": {"grid": {"kappa": [0.1, 1], "max_res": [3, 4]}},
                       "quadtree": {"rows": [{"max_points": 100}, {"max_points": 400}]}}}
    return raw | changes


@pytest.fixture(scope="module")
def spec(tmp_path_factory):
    """A 6-run grid on a 4-scan sim_lan_1 simulated into a temporary data folder."""
    data = tmp_path_factory.mktemp("data")
    return parse_spec(_raw(data_dir=str(data), output=str(data.parent / "unused")), "test")


@pytest.fixture(scope="module")
def serial(spec, tmp_path_factory):
    """``spec`` run serially into a fresh folder, once: the rows every scheduler must give
    (and the first run of the resume test, which goes on in ``serial[1]``)."""
    out = tmp_path_factory.mktemp("serial") / "runs"
    return run_sweep(spec, scheduler="serial", output=out, progress=False), out


# -- spec --------------------------------------------------------------------------------------
def test_grid_is_a_cartesian_product_plus_rows_in_order():
    runs = plan_runs(parse_spec(_raw(), "s.yaml"))
    assert [(r.mapper, dict(r.params)) for r in runs] == [
        ("alte2d", {"kappa": 0.1, "max_res": 3}), ("alte2d", {"kappa": 0.1, "max_res": 4}),
        ("alte2d", {"kappa": 1.0, "max_res": 3}), ("alte2d", {"kappa": 1.0, "max_res": 4}),
        ("quadtree", {"max_points": 100}), ("quadtree", {"max_points": 400})]
    assert all(r.terrain == "sim_lan_1" and r.frames == 4 and r.seed == 0 for r in runs)


def test_spec_defaults_and_per_mapper_terrains():
    spec = parse_spec({"terrains": "sim_lan_1", "mappers": {"alte2d": {"rows": [{}]}}}, "a.yaml")
    assert spec.name == "a" and spec.frames is None and spec.output == "reports/sweeps/a"
    raw = _raw(terrains=["sim_lan_1", "sim_nav_1"])
    raw["mappers"]["alte3d"] = {"terrains": ["sim_nav_1"], "grid": {"max_res": [3]}}
    runs = plan_runs(parse_spec(raw))
    assert {r.terrain for r in runs if r.mapper == "alte3d"} == {"sim_nav_1"}
    assert {r.terrain for r in runs if r.mapper == "alte2d"} == {"sim_lan_1", "sim_nav_1"}


def test_top_level_settings_are_a_parameter_record():
    # text values are coerced as for every parameter record (YAML strings, --set values)
    spec = parse_spec(_raw(frames="3", seeds=[2, 1, 2], voxel="0.5", name=7, output="out"))
    assert (spec.frames, spec.seeds, spec.voxel, spec.name, spec.output) == (3, (2, 1), 0.5,
                                                                              "7", "out")
    assert parse_spec(_raw(seed=5)).seeds == (5,) and parse_spec(_raw()).seeds == (0,)
    assert SweepSettings.parse({"seeds": [3, 3]}).seeds == (3,)
    assert "frames >= 1" in SweepSettings.help()["frames"]


def test_run_id_is_stable_canonical_and_sensitive():
    one = plan_runs(parse_spec(_raw()))
    again = plan_runs(parse_spec(_raw(mappers={"alte2d": {"grid": {"max_res": [3, 4],
                                                                    "kappa": [0.1, 1.0]}}})))
    assert {r.run_id for r in again} == {r.run_id for r in one if r.mapper == "alte2d"}
    assert len({r.run_id for r in one}) == 6 and all(len(r.run_id) == 64 for r in one)
    for change in ({"frames": 5}, {"seed": 1}, {"voxel": 0.5}, {"truth": {"n_samples": 10}}):
        other = plan_runs(parse_spec(_raw(**change)))
        assert not {r.run_id for r in other} & {r.run_id for r in one}, change


def test_duplicate_rows_run_once():
    raw = _raw(mappers={"quadtree": {"grid": {"max_points": [100, 100.0]},
                                     "rows": [{"max_points": 100}]}})
    assert len(plan_runs(parse_spec(raw))) == 1


def test_load_spec_reads_yaml(tmp_path):
    path = tmp_path / "g.yaml"
    path.write_text("terrains: [sim_lan_1]\nmappers:\n  quadtree:\n    grid: {max_points: [9]}\n")
    spec = load_spec(path)
    assert spec.name == "g" and spec.source == str(path) and len(plan_runs(spec)) == 1


@pytest.mark.parametrize(("raw", "match"), [
    ([1, 2], "expected a mapping"),
    (_raw(colour="red"), r"top level: unknown key\(s\) colour"),
    ({"mappers": {}}, "terrains: missing"),
    (_raw(terrains=["moon"]), r"terrains: unknown terrain\(s\) \['moon'\]"),
    (_raw(terrains=[]), "terrains: .* non-empty list"),
    (_raw(mappers=[]), "mappers: must map"),
    (_raw(mappers={"alte2d": {"kappa": [1]}}), "mappers.alte2d: needs a 'grid'"),
    (_raw(mappers={"alte2d": {"grid": {"kappa": [1]}, "x": 1}}), r"mappers.alte2d: unknown key"),
    (_raw(mappers={"alte2d": {"grid": {"kapa": [1]}}}), r"mappers.alte2d: .*unknown param.*kapa"),
    (_raw(mappers={"alte2d": {"grid": {"kappa": [-1]}}}), "mappers.alte2d: .*kappa=-1.0 out"),
    (_raw(mappers={"alte2d": {"grid": {"kappa": []}}}), "mappers.alte2d.grid.kappa: empty"),
    (_raw(mappers={"alte2d": {"grid": [1]}}), "mappers.alte2d.grid: .* must map"),
    (_raw(mappers={"alte2d": {"rows": {"kappa": 1}}}), "mappers.alte2d.rows: .* must be a list"),
    (_raw(mappers={"alte2d": {"rows": [[1]]}}), r"mappers.alte2d: \[1\] must map"),
    (_raw(mappers={"alte2d": {"rows": [{"kappa": [[1]]}]}}), "mappers.alte2d.kappa: .* number"),
    (_raw(mappers={"moon": {"rows": [{}]}}), "mappers.moon: unknown mapper 'moon'"),
    (_raw(mappers={"alte2d": {"rows": [{}], "terrains": ["sim_nav_1"]}}),
     r"mappers.alte2d.terrains: \['sim_nav_1'\] not in the top-level"),
    (_raw(frames=0), r"^bad.yaml: sweep: frames=0 out of range \(frames >= 1\)$"),
    (_raw(frames=True), "bad.yaml: sweep: frames=True is not a valid int"),
    (_raw(frames=2.5), "bad.yaml: sweep: frames=2.5 must be an integer"),
    (_raw(seed=-1), r"bad.yaml: sweep: seed=-1 out of range \(seed >= 0\)"),
    (_raw(seeds=[0, -2]), r"sweep: seeds=\[0, -2\] out of range \(a non-empty list of integers"),
    (_raw(seeds=[]), r"sweep: seeds=\[\] out of range \(a non-empty list"),
    (_raw(seeds=3), r"sweep: seeds=3 is not a list"),
    (_raw(seeds=[True]), r"sweep: seeds\[0\]=True is not a valid int"),
    (_raw(seed=1, seeds=[1]), "bad.yaml: sweep: seeds: give either seed or seeds, not both"),
    (_raw(voxel=-0.1), r"bad.yaml: sweep: voxel=-0.1 out of range \(voxel > 0\)"),
    (_raw(voxel="fine"), "bad.yaml: sweep: voxel='fine' is not a valid float"),
    (_raw(data_dir=None), "bad.yaml: sweep: data_dir=None is not a valid str"),
    (_raw(output=["a"]), r"bad.yaml: sweep: output=\['a'\] is not a valid str"),
    (_raw(truth=3), "truth: 3 must be a mapping"),
    (_raw(truth={"samples": 3}), r"truth: unknown parameter\(s\) samples; valid: grid_step"),
    (_raw(truth={"tolerance": 0}), r"truth: tolerance=0.0 out of range \(tolerance > 0\)"),
    (_raw(truth={"n_samples": "many"}), "truth: n_samples='many' is not a valid int"),
])
def test_bad_specs_name_the_key(raw, match):
    with pytest.raises(ParameterError, match=match):
        parse_spec(raw, "bad.yaml")


def test_load_spec_errors(tmp_path):
    with pytest.raises(ParameterError, match=r"sweep spec .*absent.yaml: cannot read"):
        load_spec(tmp_path / "absent.yaml")
    (tmp_path / "x.yaml").write_text("terrains: [a\n")
    with pytest.raises(ParameterError, match=r"x.yaml: invalid YAML"):
        load_spec(tmp_path / "x.yaml")
    (tmp_path / "y.yaml").write_text("terrains: [moon]\nmappers: {quadtree: {rows: [{}]}}\n")
    with pytest.raises(ParameterError, match=r"y.yaml: terrains: unknown terrain"):
        load_spec(tmp_path / "y.yaml")


def test_override():
    spec = parse_spec(_raw())
    assert override(spec, frames=None).frames is None
    assert override(spec, frames=7, data_dir=None).data_dir == spec.data_dir
    with pytest.raises(ParameterError, match=r"^sweep: frames=0 out of range \(frames >= 1\)$"):
        override(spec, frames=0)
    with pytest.raises(ParameterError, match="sweep override colour"):
        override(spec, colour=1)
    assert override(spec, seed=3).seeds == (3,)
    assert override(spec, seeds=[2, 1, 2], seed=None).seeds == (2, 1)
    assert override(spec, seeds=None).seeds == spec.seeds == (0,)
    for bad in ([], [-1]):
        with pytest.raises(ParameterError, match=r"sweep: seeds=.* out of range \(a non-empty"):
            override(spec, seeds=bad)
    with pytest.raises(ParameterError, match=r"sweep: seeds\[0\]=True is not a valid int"):
        override(spec, seeds=[True])
    with pytest.raises(ParameterError, match=r"sweep: seeds='0' is not a list"):
        override(spec, seeds="0")
    with pytest.raises(ParameterError, match="sweep: seeds: give either seed or seeds"):
        override(spec, seed=1, seeds=[2])


# -- store -------------------------------------------------------------------------------------
def test_store_unifies_columns_orders_and_never_overwrites(tmp_path):
    out = tmp_path / "runs"
    assert finished_ids(out) == set() and load_results(out).empty
    write_row(out, {"run_id": "b", "mapper": "alte2d", "p_kappa": 0.1, "hd_m": 1.0,
                    "elapsed_s": 0.5})
    write_row(out, {"run_id": "a", "mapper": "quadtree", "p_max_points": 7, "hd_m": 2.0,
                    "wall_s": 1.0})
    (out / ".run-c.parquet.x.part").write_bytes(b"partial")  # an interrupted write
    assert finished_ids(out) == {"a", "b"}
    table = load_results(out)
    assert list(table["run_id"]) == ["a", "b"]
    assert list(table.columns) == ["run_id", "mapper", "p_kappa", "p_max_points", "hd_m",
                                   "elapsed_s", "wall_s"]
    assert table["p_max_points"].dtype == "Int64" and pd.isna(table["p_max_points"][1])
    assert list(load_results(out, ["b", "zz", "a"])["run_id"]) == ["b", "a"]
    with pytest.raises(AlteError, match="already exists"):
        write_row(out, {"run_id": "a", "hd_m": 3.0})


def test_rows_stored_before_the_poses_column_read_as_recorded(tmp_path):
    out = tmp_path / "runs"
    write_row(out, {"run_id": "old", "hd_m": 1.0})
    write_row(out, {"run_id": "new", "hd_m": 2.0, "poses": "odometry"})
    assert load_results(out).set_index("run_id")["poses"].to_dict() == {
        "new": "odometry", "old": "recorded"}


def test_store_errors(tmp_path):
    (tmp_path / "file").write_text("x")
    with pytest.raises(AlteError, match="is a file, not a Parquet dataset folder"):
        finished_ids(tmp_path / "file")
    (tmp_path / "runs").mkdir()
    (tmp_path / "runs" / "run-bad.parquet").write_text("not parquet")
    with pytest.raises(AlteError, match=r"run-bad.parquet is unreadable"):
        load_results(tmp_path / "runs")


# -- running -----------------------------------------------------------------------------------
def test_serial_sweep_writes_rows_and_resumes(spec, serial):
    first, out = serial
    assert (first.ran, first.skipped, first.failed) == (6, 0, [])
    table = first.table
    assert list(table["run_id"]) == [r.run_id for r in plan_runs(spec)]
    assert list(table["mapper"]) == ["alte2d"] * 4 + ["quadtree"] * 2
    assert table["frames"].eq(4).all() and table["frames_requested"].eq(4).all()
    assert table[["hd_m", "mhd_m", "basis_functions", "completeness"]].notna().all().all()
    # runs sharing a map share its feed: each one's cost holds its share of it
    assert (table["elapsed_s"] > 0).all()
    shares = table.groupby("elapsed_s")["wall_s"].sum()
    assert (shares >= shares.index).all()
    assert list(table.columns[-len(TIMING_COLUMNS):]) == list(TIMING_COLUMNS)
    assert (table["cpu_s"] > 0).all()
    # max_res 4 refines more than max_res 3: more basis functions
    assert table["basis_functions"][1] > table["basis_functions"][0]
    # the first table is made of the rows as written, the second read back from the files
    again = run_sweep(spec, scheduler="none", output=out, progress=False)
    assert (again.ran, again.skipped) == (0, 6)
    pd.testing.assert_frame_equal(again.table, table, check_exact=True)
    (out / f"run-{table['run_id'][2]}.parquet").unlink()  # as if killed before that run
    third = run_sweep(spec, scheduler="serial", output=out, progress=False)
    assert (third.ran, third.skipped) == (1, 5)
    keep = [c for c in table.columns if c not in TIMING_COLUMNS]
    pd.testing.assert_frame_equal(third.table[keep], table[keep], check_exact=True)


def test_failed_runs_are_reported_not_written_and_retried(spec, tmp_path, monkeypatch):
    real = sweep_groups.measure_map

    def flaky(mapper, cloud, **kw):
        if mapper.name == "quadtree":
            raise MemoryError("boom")
        return real(mapper, cloud, **kw)

    monkeypatch.setattr(sweep_groups, "measure_map", flaky)
    result = run_sweep(spec, scheduler="serial", output=tmp_path, progress=False)
    assert result.ran == 4 and len(result.table) == 4
    assert [(r.mapper, msg) for r, msg in result.failed] == [("quadtree", "MemoryError: boom")] * 2
    assert result.summary()["failed"][0]["params"] == {"max_points": 100}
    monkeypatch.setattr(sweep_groups, "measure_map", real)
    retry = run_sweep(spec, scheduler="serial", output=tmp_path, progress=False)
    assert (retry.ran, retry.skipped, retry.failed) == (2, 4, [])


def test_scheduler_errors(spec, tmp_path, monkeypatch):
    with pytest.raises(ParameterError, match="sweep: scheduler='cluster': expected serial"):
        run_sweep(spec, scheduler="cluster", output=tmp_path, progress=False)
    with pytest.raises(ParameterError, match=r"sweep: workers=0 out of range \(workers >= 1\)"):
        run_sweep(spec, scheduler="local", workers=0, output=tmp_path, progress=False)
    monkeypatch.setattr(sweep_runner, "CONNECT_TIMEOUT", "0.5s")
    with pytest.raises(ParameterError, match=r"sweep: scheduler=tcp://127.0.0.1:9: cannot connect"):
        run_sweep(spec, scheduler="tcp://127.0.0.1:9", output=tmp_path, progress=False)


def test_unknown_terrain_simulation_failure_is_named(spec, tmp_path, monkeypatch):
    def broken(*args, **kwargs):
        raise OSError("disk full")

    monkeypatch.setattr(alte.sim, "ensure_terrain", broken)
    with pytest.raises(AlteError, match=r"terrain sim_lan_1 .*could not be simulated: disk full"):
        run_sweep(spec, scheduler="serial", output=tmp_path, progress=False)


@pytest.mark.full
def test_local_cluster_gives_the_serial_rows(spec, serial, tmp_path):
    """Same grid, serial vs LocalCluster(2 workers). ``make check-full``'s: its parts are
    proven in ``make test`` by ``sensor/test_sensor.py::test_seeds_give_a_row_each...`` (the
    ``local`` executor, two worker processes, the serial rows), ``test_dask_cluster.py``
    (a sweep on worker processes gives the serial rows) and
    ``test_existing_scheduler_address`` below."""
    table = serial[0].table
    dask = run_sweep(spec, scheduler="local", workers=2, output=tmp_path / "b", progress=False)
    assert dask.ran == 6 and not dask.failed
    keep = [c for c in table.columns if c not in TIMING_COLUMNS]
    pd.testing.assert_frame_equal(dask.table[keep], table[keep], check_exact=True)


@pytest.mark.slow
def test_existing_scheduler_address(spec, serial, tmp_path):
    from distributed import LocalCluster

    from alte.lab.studies.sweep.runner import CLUSTER_OPTIONS

    threads = {k: v for k, v in CLUSTER_OPTIONS.items() if k != "env"}  # for processes
    with LocalCluster(n_workers=1, **{**threads, "processes": False}) as cluster:
        result = run_sweep(spec, scheduler=cluster.scheduler_address, output=tmp_path,
                           progress=False)
    table = serial[0].table
    keep = [c for c in table.columns if c not in TIMING_COLUMNS]
    pd.testing.assert_frame_equal(result.table[keep], table[keep], check_exact=True)


# -- analysis ----------------------------------------------------------------------------------
def _grid_table():
    rows = [{"mapper": "alte2d", "terrain": "t", "p_kappa": k, "p_max_res": r, "p_min_pts": m,
             "mhd_m": k * 10 + r + m / 100}
            for k in (0.1, 1.0) for r in (4, 5, 6) for m in (10, 100)]
    rows.append({"mapper": "quadtree", "terrain": "t", "p_max_points": 5, "mhd_m": 1.0})
    return pd.DataFrame(rows)


def test_sensitivity_table_pivots_and_averages():
    table = _grid_table()
    grid = sensitivity_table(table, "alte2d", "kappa", "max_res", "mhd_m", fixed={"min_pts": 10})
    assert list(grid.columns) == [0.1, 1.0] and list(grid.index) == [4, 5, 6]
    assert grid.loc[5, 1.0] == pytest.approx(15.1)
    mean = sensitivity_table(table, "alte2d", "kappa", "max_res", "mhd_m", terrain="t")
    assert mean.loc[5, 1.0] == pytest.approx(15.55)


def test_main_effects_and_ranking():
    table = _grid_table()
    effects = main_effects(table, "alte2d", "mhd_m")
    assert list(dict.fromkeys(effects["param"])) == ["kappa", "max_res", "min_pts"]
    kappa = effects[effects["param"] == "kappa"]
    assert kappa["mean"].diff().iloc[1] == pytest.approx(9.0) and kappa["runs"].eq(6).all()
    ranking = sensitivity_ranking(table, ["mhd_m"])
    assert list(ranking["param"]) == ["kappa", "max_res", "min_pts"]  # quadtree sweeps nothing
    assert ranking["spread"].tolist() == pytest.approx([9.0, 2.0, 0.9])


def test_analysis_errors():
    table = _grid_table()
    with pytest.raises(ParameterError, match="no alte3d rows"):
        sensitivity_table(table, "alte3d", "max_res", "min_pts", "mhd_m")
    with pytest.raises(ParameterError, match="alte2d has no parameter 'colour' to fix"):
        sensitivity_table(table, "alte2d", "kappa", "max_res", "mhd_m", fixed={"colour": 1})
    with pytest.raises(ParameterError, match=r"no column\(s\) \['hd_m'\]"):
        sensitivity_table(table, "alte2d", "kappa", "max_res", "hd_m")
    with pytest.raises(ParameterError, match="no quadtree parameter takes more than one value"):
        main_effects(table, "quadtree", "mhd_m")
    with pytest.raises(ParameterError, match=r"none of .*quadtree.* sweeps"):
        sensitivity_ranking(table, ["mhd_m"], mappers=["quadtree"])
