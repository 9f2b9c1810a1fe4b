"""Tests for alte.studies.analysis: experiments, comparison rule, tables and figures."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from alte.errors import ParameterError
from alte.metrics import TrueSurface
from alte.studies.analysis import (
    Dataset,
    TruthOptions,
    best_row,
    comparison_scores,
    comparison_table,
    map_grid_figure,
    point_cloud_table,
    qualitative_table,
    run_mapper,
    sweep,
    thesis_metrics,
    trend_table,
    write_table,
)


def _steps_dataset(frames: int = 4) -> Dataset:
    """A 16 x 16 m ground with a 2 m high 4 x 4 m block, scanned as dense random points."""
    rng = np.random.default_rng(0)
    xy = rng.uniform(0, 16, (8000, 2))
    z = np.where(np.all((xy > 6) & (xy < 10), axis=1), 2.0, 0.0)
    cloud = np.column_stack([xy, z])
    parts = np.array_split(cloud, frames)
    origins = np.tile([8.0, 8.0, 10.0], (frames, 1))
    verts = np.array([[0, 0, 0], [16, 0, 0], [16, 16, 0], [0, 16, 0],
                      [6, 6, 2], [10, 6, 2], [10, 10, 2], [6, 10, 2]], float)
    tris = np.array([[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]])
    surface = TrueSurface(verts, tris, np.array([0, 0, 1, 1]), {0: "ground", 1: "roof"},
                          {0: "ground", 1: "building"})
    bounds = np.array([[0, 0, -1], [16, 16, 5]], float)
    return Dataset("steps", "lan", list(zip(parts, origins, strict=True)), cloud, origins,
                   surface, bounds, {"frames": frames, "points": len(cloud)})


def test_run_mapper_times_and_measures_2d_maps():
    data = _steps_dataset()
    for name, params in [("quadtree", {"max_points": 50}), ("alte2d", {"max_res": 4})]:
        run = run_mapper(data, name, params, truth=TruthOptions(grid_step=0.5))
        m = run.metrics
        assert m["elapsed_s"] > 0 and m["basis_functions"] == run.mapper.basis_functions
        assert m["hd_m"] >= m["mhd_m"] >= 0
        assert m["hd_minus_mhd_m"] == pytest.approx(m["hd_m"] - m["mhd_m"])
        assert 0 <= m["unknown_share"] <= 1 and m["completeness"] > 0.5
        assert m["height_rmse_m"] < 1.0


def test_run_mapper_without_truth_has_only_thesis_metrics():
    run = run_mapper(_steps_dataset(), "quadtree", {"max_points": 200})
    assert "completeness" not in run.metrics and "mhd_m" in run.metrics


def test_sweep_puts_our_metrics_beside_the_thesis_columns():
    table, runs = sweep(_steps_dataset(), 7, rows=[0, 5], progress=False)
    assert table["max_points"].tolist() == [25, 1000]
    assert table["thesis_row"].tolist() == [0, 5]
    assert table["thesis_elapsed_s"].tolist() == [43.38, 0.62]
    assert len(runs) == 2 and runs[0].metrics["basis_functions"] > runs[1].metrics[
        "basis_functions"]


@pytest.mark.parametrize(("table", "rows", "match"), [(5, None, "not a sweep"),
                                                     (7, [6], r"rows \[6\] not in 0..5"),
                                                     (7, [], r"rows \[\] not in 0..5")])
def test_sweep_rejects_bad_tables_and_rows(table, rows, match):
    with pytest.raises(ParameterError, match=match):
        sweep(_steps_dataset(), table, rows=rows, progress=False)


def test_comparison_rule_on_the_thesis_numbers():
    # The rule reproduces the thesis' 3D-ALTE choice (row 3 of table 5.12) ...
    assert best_row(thesis_metrics(12)) == 2
    # ... and is invariant to the units of a criterion.
    t = thesis_metrics(8)
    scaled = t.assign(elapsed_s=t["elapsed_s"] * 1000)
    np.testing.assert_allclose(comparison_scores(t), comparison_scores(scaled))


def test_comparison_rule_prefers_a_dominating_row():
    table = pd.DataFrame({"elapsed_s": [2.0, 1.0, 3.0], "basis_functions": [20, 10, 5],
                          "mhd_m": [0.5, 0.4, 0.9], "hd_minus_mhd_m": [1.0, 1.0, 1.0]})
    assert best_row(table) == 1


@pytest.mark.parametrize(("table", "match"), [(pd.DataFrame({"elapsed_s": [1.0]}), "lacks"),
                                              (pd.DataFrame(columns=["elapsed_s",
                                                                     "basis_functions",
                                                                     "mhd_m",
                                                                     "hd_minus_mhd_m"]),
                                               "no rows")])
def test_comparison_rule_rejects_bad_tables(table, match):
    with pytest.raises(ParameterError, match=match):
        best_row(table)


def _thesis_as_ours(number: int) -> pd.DataFrame:
    table = thesis_metrics(number)
    table["thesis_row"] = range(len(table))
    return table


def test_comparison_table_on_thesis_numbers_agrees_with_rule_on_thesis():
    sweeps = {"octomap": _thesis_as_ours(8), "alte3d": _thesis_as_ours(12)}
    table = comparison_table(11, sweeps)
    assert (table["params"] == table["rule_on_thesis"]).all()
    row = table.set_index("mapper").loc["alte3d"]
    assert row["thesis_params"] == "min_pts=5, min_pts_split=10, max_res=5"
    assert row["thesis_elapsed_s"] == 11.59
    with pytest.raises(ParameterError, match="needs the alte3d sweep"):
        comparison_table(11, {"octomap": sweeps["octomap"]})
    with pytest.raises(ParameterError, match="not a comparison"):
        comparison_table(9, sweeps)


def test_trend_table_on_thesis_numbers():
    trends = trend_table(8, _thesis_as_ours(8))
    assert (trends["holds_on_ours"] == trends["holds_in_thesis"]).all()
    assert trends.set_index("trend").loc["basis functions rise with resolution",
                                         "holds_in_thesis"]
    comp = comparison_table(10, {"quadtree": _thesis_as_ours(7), "alte2d": _thesis_as_ours(9)})
    assert len(trend_table(10, comp)) == 3
    with pytest.raises(ParameterError, match="states no trends"):
        trend_table(5, comp)


def test_point_cloud_table_and_write_table(tmp_path):
    table = point_cloud_table(5, "sim_nav_1", 40, 1234)
    assert table.loc[0, "thesis_points"] == 381187
    path = write_table(table, tmp_path, 5)
    assert path.name == "table_5_5.csv" and pd.read_csv(path).loc[0, "frames"] == 40
    with pytest.raises(Exception, match="already exists"):
        write_table(table, tmp_path, 5)
    write_table(table, tmp_path, 5, overwrite=True)
    with pytest.raises(ParameterError, match="not a point-cloud table"):
        point_cloud_table(7, "x", 1, 1)


def test_qualitative_table_marks_sources():
    best = {"octomap": {"size_octaves": 0.0, "hd_minus_mhd_m": 3.0, "basis_functions": 1000,
                        "free_truly_free_share": 0.97},
            "alte3d": {"size_octaves": 4.0, "hd_minus_mhd_m": 1.0, "basis_functions": 100,
                       "free_truly_free_share": float("nan")}}
    inputs = {m: {"best": b, "sweep_mhd": [0.4, 0.41, 0.39] if m == "octomap" else [0.2, 0.6],
                  "incremental": True} for m, b in best.items()}
    t2 = qualitative_table(2, inputs).set_index("mapper")
    assert t2.loc["octomap", "adaptability"] == "Low" and t2.loc["alte3d", "adaptability"] == "High"
    assert t2.loc["octomap", "robustness"] == "High" and t2.loc["alte3d", "robustness"] == "Low"
    assert t2.loc["alte3d", "outlier_rejection"] == "High"
    assert t2.loc["octomap", "outlier_rejection"] == "Low"
    assert t2.loc["octomap", "development_source"] == "thesis"
    t4 = qualitative_table(4, inputs).set_index("mapper")
    assert t4.loc["alte3d", "free_space_mapping"] == "No"
    assert t4.loc["alte3d", "free_space_mapping_source"] == "thesis"
    assert t4.loc["alte3d", "map_size"] == "Mid"
    assert t4.loc["alte3d", "overhanging_structures_source"].startswith("thesis (no measurement")


def test_map_grid_figure_draws_one_panel_per_map():
    data = _steps_dataset()
    runs = [run_mapper(data, "alte2d", {"max_res": r}) for r in (2, 4)]
    fig = map_grid_figure([r.mapper for r in runs], ["a", "b"], columns=3)
    visible = [ax for ax in fig.axes if ax.get_visible() and ax.get_title()]
    assert [ax.get_title() for ax in visible] == ["a", "b"]


def test_load_dataset_reads_a_simulated_terrain(tmp_path):
    from alte.sim import ensure_terrain
    from alte.studies.analysis import load_dataset

    folder = ensure_terrain("sim_lan_2", out_dir=tmp_path, frames=6)
    data = load_dataset(folder, frames=3)
    assert data.case == "lan" and data.info["frames_in_bag"] == 6 and data.info["frames"] == 3
    assert data.cloud.shape[1] == 3 and len(data.frames) == 3 and data.bounds.shape == (2, 3)
    assert np.all(data.surface.distance(data.cloud) < 1.0)
    with pytest.raises(ParameterError, match="frames=0"):
        load_dataset(folder, frames=0)


def test_alte3d_gets_the_control_volume_cube_as_domain():
    data = _steps_dataset()
    data.case = "nav"
    run = run_mapper(data, "alte3d", {"max_res": 4, "min_pts": 2, "min_pts_split": 5,
                                      "occupancy_level": 4},
                     truth=TruthOptions(n_samples=2000))
    assert "domain" not in run.params
    assert run.metrics["basis_functions"] > 0 and 0 < run.metrics["completeness"] <= 1
    domain = [float(v) for v in run.mapper.params["domain"].split(",")]
    assert domain[:3] == [0.0, 0.0, -1.0] and 16.0 < domain[3] < 16.0 + 1e-6  # covers hi


def test_comparison_rule_skips_rows_with_missing_criteria():
    table = pd.DataFrame({"elapsed_s": [1.0, 2.0, 3.0], "basis_functions": [1, 20, 30],
                          "mhd_m": [np.nan, 0.5, 0.6], "hd_minus_mhd_m": [np.nan, 1.0, 1.0]})
    assert best_row(table) == 1 and np.isinf(comparison_scores(table)[0])
    with pytest.raises(ParameterError, match="no row has every criterion"):
        best_row(table.iloc[:1])


def test_empty_map_gets_nan_hausdorff():
    data = _steps_dataset()
    run = run_mapper(data, "alte3d", {"max_res": 2, "min_pts": 10_000, "min_pts_split": 5})
    assert run.metrics["occupied_cells"] == 0 and np.isnan(run.metrics["mhd_m"])
