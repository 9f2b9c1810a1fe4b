"""Trade-off tables: schema, parameters, Pareto fronts and reads at equal size/fidelity."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from support.tradeoff import Curve, synthetic_tradeoff

from alte.errors import ParameterError
from alte.lab.studies.analysis.tradeoff import (
    REQUIRED_COLUMNS,
    equal_fidelity,
    equal_size,
    fronts,
    interval_table,
    label,
    pareto_front,
    parse_params,
    prepare,
    read_at_size,
    size_for_fidelity,
)


def test_pareto_front_is_the_lower_left_envelope():
    x = np.array([10, 1, 5, 5, 2, 20, np.nan, 8])
    y = np.array([1, 9, 3, 2, 8, 1, 0, 2.5])
    front = pareto_front(x, y)
    assert front.tolist() == [1, 4, 3, 0]  # (1,9) (2,8) (5,2) (10,1); (20,1) and (8,2.5) lose
    assert pareto_front(np.array([np.nan]), np.array([1.0])).size == 0


def test_read_at_size_interpolates_in_log_size_and_never_extrapolates():
    xs, ys = np.array([100.0, 10_000.0]), np.array([2.0, 1.0])
    got = read_at_size(xs, ys, [10, 100, 1000, 10_000, 50_000])
    assert np.isnan(got[0]) and np.isnan(got[-1])
    assert got[1:4] == pytest.approx([2.0, 1.5, 1.0])
    # flat beyond the last front point up to the largest map made
    assert read_at_size(xs, ys, [50_000], x_max=60_000)[0] == pytest.approx(1.0)


def test_size_for_fidelity_inverts_the_front():
    xs, ys = np.array([100.0, 10_000.0]), np.array([2.0, 1.0])
    got = size_for_fidelity(xs, ys, [2.5, 2.0, 1.5, 1.0, 0.5])
    assert np.isnan(got[0]) and np.isnan(got[-1])
    assert got[1:4] == pytest.approx([100, 1000, 10_000])


def test_parse_params_reads_json_and_key_value_text():
    assert parse_params('{"kappa": 0.1, "max_res": 5}') == {"kappa": 0.1, "max_res": 5}
    assert parse_params("kappa=0.1, max_res=5, model=matlab") == {
        "kappa": 0.1, "max_res": 5.0, "model": "matlab"}
    with pytest.raises(ParameterError, match="expected k=v"):
        parse_params("kappa")
    with pytest.raises(ParameterError, match="is not JSON"):
        parse_params("{kappa")


def test_prepare_checks_the_schema_and_derives_columns():
    table = synthetic_tradeoff(seeds=(0,))
    out = prepare(table.drop(columns=["hd_minus_mhd_m"], errors="ignore"))
    assert {"p_max_points", "p_kappa", "p_resolution", "hd_minus_mhd_m", "free_share"} <= set(out)
    octomap = out[out["mapper"] == "octomap"]
    assert octomap["free_share"].to_numpy() == pytest.approx(0.7, abs=0.01)
    with pytest.raises(ParameterError, match=r"lacks column.*mhd_m, hd_m; it needs terrain"):
        prepare(table.drop(columns=["mhd_m", "hd_m"]))
    assert len(REQUIRED_COLUMNS) == 12
    swept = prepare(table.rename(columns={"params": "params_json"}))
    assert swept["params"].equals(swept["params_json"])


def test_fronts_flag_each_seeds_front():
    table = synthetic_tradeoff({"quadtree": Curve()}, seeds=(0, 1))
    marked = fronts(table[table["mapper"] == "quadtree"])
    assert set(marked.columns) == {"terrain", "mapper", "seed", "params", "x", "y", "on_front"}
    assert marked["on_front"].sum() >= 2 * 2 * 5  # a clean power law: most maps are on it
    with pytest.raises(ParameterError, match="no column"):
        fronts(table, metric="nope")


def test_equal_size_reads_the_winner_and_the_auto_levels_lie_in_the_overlap():
    table = synthetic_tradeoff({"alte2d": Curve(scale=0.5)})
    reads = equal_size(table, ("quadtree", "alte2d"))
    assert set(reads["terrain"]) == {"sim_lan_1", "sim_lan_2"}
    assert reads.groupby("terrain")["level"].nunique().tolist() == [3, 3]
    wide = reads.pivot_table(index=["terrain", "level", "seed"], columns="mapper", values="value")
    assert (wide["alte2d"] < wide["quadtree"]).all()
    ratio = (wide["quadtree"] / wide["alte2d"]).to_numpy()
    assert ratio == pytest.approx(2.0, rel=0.1)
    fixed = equal_size(table, ("quadtree", "alte2d"), levels=[2000, 10**9])
    assert fixed[fixed["level"] == 10**9]["value"].isna().all()


def test_equal_fidelity_reads_sizes_and_completeness_counts_higher_as_better():
    table = synthetic_tradeoff({"alte2d": Curve(scale=0.5)})
    reads = equal_fidelity(table, ("quadtree", "alte2d"))
    wide = reads.pivot_table(index=["terrain", "level", "seed"], columns="mapper", values="value")
    # MHD = s (n/1000)^-0.3: half the scale needs 2^(1/0.3) ~ 10x fewer basis functions
    ratio = (wide["quadtree"] / wide["alte2d"]).to_numpy()
    assert np.exp(np.log(ratio).mean()) == pytest.approx(10.08, rel=0.05)
    assert ((ratio > 7) & (ratio < 14)).all()
    up = equal_size(table, ("quadtree", "alte2d"), "completeness", higher_is_better=True)
    wide = up.pivot_table(index=["terrain", "level", "seed"], columns="mapper", values="value")
    assert (wide["alte2d"] > wide["quadtree"]).all()


def test_a_terrain_missing_a_mapper_is_left_out():
    table = synthetic_tradeoff(terrains={"alte2d": ("sim_lan_1",)})
    assert set(equal_size(table, ("quadtree", "alte2d"))["terrain"]) == {"sim_lan_1"}
    assert equal_size(table, ("quadtree", "nope")).empty


def test_interval_table_summarises_seeds():
    reads = pd.DataFrame({"terrain": "t", "level": 1.0, "mapper": "m", "seed": [0, 1, 2],
                          "value": [1.0, 2.0, 3.0]})
    row = interval_table(reads).iloc[0]
    assert row["mean"] == pytest.approx(2.0) and row["seeds"] == 3
    assert 1.0 <= row["low"] < 2.0 < row["high"] <= 3.0


def test_labels_carry_units():
    assert label("mhd_m") == "MHD [m]" and label("mhd_m", unit=False) == "MHD"
    assert label("basis_functions") == "basis functions" and label("other") == "other"
