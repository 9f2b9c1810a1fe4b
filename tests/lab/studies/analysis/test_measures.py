"""Per-seed statistics of each kind of check, on small hand-made trade-off tables."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from support.tradeoff import sweep_rows, synthetic_tradeoff

from alte.errors import ParameterError
from alte.lab.studies.analysis.measures import NoDataError, measure_check
from alte.lab.studies.analysis.tradeoff import prepare, thesis_setting
from alte.lab.studies.thesis.claims import (
    Agreement,
    Compare,
    Effect,
    NotMeasurable,
    Optimum,
    Summary,
    Trend,
)


def _table(mapper: str, xs: list[float], metric: dict[str, list[float]], *, param: str = "x",
           seeds: tuple[int, ...] = (0, 1), terrain: str = "sim_lan_1") -> pd.DataFrame:
    return prepare(sweep_rows(mapper, xs, metric, param=param, seeds=seeds, terrain=terrain))


def test_trend_is_spearman_rho_of_the_level_means_times_the_stated_sign():
    table = _table("quadtree", [10, 20, 30, 40], {"mhd_m": [1.0, 1.2, 1.1, 1.5]},
                   param="max_points")
    m = measure_check(Trend("lan", "quadtree", "max_points", "mhd_m", +1), table)
    assert m.stats["value"].to_numpy() == pytest.approx([0.8, 0.8])
    assert m.threshold == 0.5 and "Spearman rho of MHD [m] with max_points" in m.what
    falls = measure_check(Trend("lan", "quadtree", "max_points", "mhd_m", -1), table)
    assert falls.stats["value"].to_numpy() == pytest.approx([-0.8, -0.8])


def test_trend_over_the_larger_maps_only():
    table = _table("quadtree", [1, 2, 3, 4], {"mhd_m": [4.0, 3.0, 1.0, 2.0]})
    m = measure_check(Trend("lan", "quadtree", "basis_functions", "mhd_m", +1, largest_half=True),
                table)
    assert np.isnan(m.stats["value"]).all()  # two maps: no rank trend
    table = _table("quadtree", [1, 2, 3, 4, 5, 6], {"mhd_m": [4.0, 3.0, 1.0, 1.5, 2.0, 2.5]})
    m = measure_check(Trend("lan", "quadtree", "basis_functions", "mhd_m", +1, largest_half=True),
                table)
    assert m.stats["value"].to_numpy() == pytest.approx([1.0, 1.0])


def test_optimum_compares_the_finest_setting_with_the_best_interior_one():
    table = _table("quadtree", [25, 100, 500, 1000], {"mhd_m": [1.2, 1.0, 1.3, 1.1]},
                   param="max_points")
    m = measure_check(Optimum("lan", "quadtree", "max_points", "mhd_m", "low"), table)
    assert m.stats["value"].to_numpy() == pytest.approx([0.2, 0.2]) and m.unit == "m"
    m = measure_check(Optimum("lan", "quadtree", "max_points", "mhd_m", "high"), table)
    assert m.stats["value"].to_numpy() == pytest.approx([0.1, 0.1])


def test_effect_compares_relative_spreads_of_two_parameters():
    table = synthetic_tradeoff(seeds=(0,))
    table = prepare(table)
    m = measure_check(Effect("lan", "alte2d", "basis_functions", "max_res", other="kappa"), table)
    assert (m.stats["value"] > 1).all()
    m = measure_check(Effect("lan", "alte2d", "basis_functions", "min_pts", max_spread=0.1), table)
    assert (m.stats["value"] > 0).all() and "0.1 minus" in m.what
    with pytest.raises(NoDataError, match="no parameter or column 'nope'"):
        measure_check(Effect("lan", "alte2d", "basis_functions", "nope"), table)


def test_effect_holds_the_other_parameters_fixed():
    """A parameter that changes nothing at fixed other settings has no effect, even when
    rows off the balanced grid would make its level means differ (a confound)."""
    rows = [{"terrain": "sim_lan_1", "seed": 0, "mapper": "alte3d", "p_max_res": r,
             "p_min_pts": m, "basis_functions": 10.0 ** r}
            for r in (4, 5, 6) for m in (5, 20)]
    rows.append({"terrain": "sim_lan_1", "seed": 0, "mapper": "alte3d", "p_max_res": 5,
                 "p_min_pts": 40, "basis_functions": 1e5})  # a thesis row at max_res 5 only
    table = pd.DataFrame(rows).assign(case="lan")
    m = measure_check(Effect("lan", "alte3d", "basis_functions", "min_pts", max_spread=0.1), table)
    assert m.stats["value"].to_numpy() == pytest.approx([0.1])  # no spread at all
    m = measure_check(Effect("lan", "alte3d", "basis_functions", "max_res", other="min_pts"), table)
    assert m.stats["value"].iloc[0] > 1


def test_agreement_with_the_ground_truth():
    table = _table("quadtree", [1, 2, 3, 4], {"mhd_m": [1.0, 2.0, 3.0, 4.0],
                                             "hd_m": [5.0, 3.0, 6.0, 4.0],
                                             "height_rmse_m": [0.1, 0.2, 0.3, 0.5]})
    m = measure_check(Agreement("lan", "quadtree", "mhd_m", "height_rmse_m", other="hd_m"), table)
    assert m.stats["value"].to_numpy() == pytest.approx([1.0, 1.0])  # rho 1 vs rho 0
    m = measure_check(Agreement("lan", "quadtree", "mhd_m", "completeness", sign=-1), table)
    assert np.isnan(m.stats["value"]).all()  # completeness constant: no agreement defined


def test_summary_medians_and_coefficients_of_variation():
    a = _table("alte2d", [1, 2, 3], {"mhd_m": [1.0, 1.0, 1.0], "size_octaves": [4, 5, 6]})
    b = _table("quadtree", [1, 2, 3], {"mhd_m": [1.0, 2.0, 3.0], "size_octaves": [1, 2, 3]})
    table = pd.concat([a, b], ignore_index=True)
    m = measure_check(Summary("lan", "alte2d", "size_octaves", "median", "quadtree",
                        higher_is_better=True), table)
    assert m.stats["value"].to_numpy() == pytest.approx([3.0, 3.0])
    m = measure_check(Summary("lan", "alte2d", "mhd_m", "cv", "quadtree"), table)
    assert m.stats["value"].to_numpy() == pytest.approx([np.std([1, 2, 3]) / 2] * 2)
    assert "coefficient of variation of MHD [m] over the settings, Quadtree minus 2D-ALTE" in (
        m.what)


def test_compare_at_the_thesis_point_needs_the_thesis_setting():
    assert thesis_setting("quadtree") == {"max_points": 150}
    assert thesis_setting("alte3d") == {"min_pts": 5, "min_pts_split": 10, "max_res": 5}
    assert thesis_setting("nope") is None
    table = prepare(synthetic_tradeoff())
    m = measure_check(Compare("lan", "alte2d", "quadtree", "basis_functions", "thesis_point"),
                      table)
    assert m.ratio and m.unit == "x" and len(m.stats) == 2 * 3
    lacking = table[~((table["mapper"] == "quadtree") & (table["p_max_points"] == 150))]
    with pytest.raises(NoDataError, match="lacks the thesis' setting quadtree max_points=150"):
        measure_check(Compare("lan", "alte2d", "quadtree", "mhd_m", "thesis_point"), lacking)


def test_compare_names_what_is_missing():
    table = prepare(synthetic_tradeoff())
    with pytest.raises(NoDataError, match="no rows of octomap on the lan terrains"):
        measure_check(Compare("lan", "alte2d", "octomap", "mhd_m", "equal_size"), table)
    with pytest.raises(NoDataError, match=r"no values in column\(s\) height_rmse_m"):
        measure_check(Compare("nav", "alte3d", "octomap", "height_rmse_m", "equal_size"), table)
    with pytest.raises(ParameterError, match="NotMeasurable checks are not measured"):
        measure_check(NotMeasurable("because"), table)


def test_a_case_column_overrides_the_thesis_terrains():
    table = prepare(synthetic_tradeoff(terrains={"quadtree": ("mine",), "alte2d": ("mine",)}))
    table["case"] = np.where(table["mapper"].isin(["quadtree", "alte2d"]), "lan", "nav")
    m = measure_check(Compare("lan", "alte2d", "quadtree", "mhd_m", "equal_size"), table)
    assert set(m.stats["terrain"]) == {"mine"}
