"""The per-seed statistics at their edges, what each says in words, and time judged on cost.

Expected values are worked out by hand in the comments; none is computed with the
function under test.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from support.tradeoff import sweep_rows

from alte.lab.studies.analysis.checks import STAT_COLUMNS
from alte.lab.studies.analysis.measures import NoDataError, measure_check
from alte.lab.studies.analysis.tradeoff import prepare
from alte.lab.studies.thesis.claims import Agreement, Effect, Optimum, Summary, Trend
from alte.lab.studies.thesis.claims.types import Contrast


def _table(xs: list[float], metric: dict[str, list[float]], *, mapper: str = "quadtree",
           param: str = "max_points", seeds: tuple[int, ...] = (0, 1)) -> pd.DataFrame:
    return prepare(sweep_rows(mapper, xs, metric, param=param, seeds=seeds))


def _values(check, table: pd.DataFrame) -> list[float]:
    return measure_check(check, table).stats["value"].tolist()


FOUR = {"mhd_m": [1.0, 1.2, 1.1, 1.5]}

WORDS = [
    (Trend("lan", "quadtree", "max_points", "mhd_m", -1, largest_half=True),
     "Spearman rho of MHD [m] with max_points over the larger half of Quadtree's maps, "
     "times the stated sign (-1)", ""),
    (Trend("lan", "quadtree", "max_points", "mhd_m", +1),
     "Spearman rho of MHD [m] with max_points over Quadtree's maps, times the stated sign (+1)",
     ""),
    (Optimum("lan", "quadtree", "max_points", "mhd_m", "low"),
     "MHD [m] of Quadtree at the finest max_points minus the best interior setting", "m"),
    (Effect("lan", "quadtree", "mhd_m", "max_points"),
     "0 minus the relative spread of MHD [m] over max_points (Quadtree)", ""),
    (Effect("lan", "quadtree", "mhd_m", "max_points", max_spread=0.25),
     "0.25 minus the relative spread of MHD [m] over max_points (Quadtree)", ""),
    (Agreement("lan", "quadtree", "mhd_m", "completeness"),
     "0.5 minus the agreement (Spearman rho) of MHD [m] with completeness, over Quadtree's "
     "settings", ""),
    (Agreement("lan", "quadtree", "mhd_m", "completeness", other="hd_m"),
     "agreement (Spearman rho) with completeness of MHD [m] minus that of HD [m], over "
     "Quadtree's settings", ""),
]


@pytest.mark.parametrize(("check", "what", "unit"), WORDS)
def test_each_check_says_what_it_measures(check, what: str, unit: str) -> None:
    found = measure_check(check, _table([10, 20, 30, 40], FOUR))
    assert (found.what, found.unit, found.time) == (what, unit, "")
    assert list(found.stats.columns) == STAT_COLUMNS


def test_per_seed_rows_come_sorted_by_terrain_then_seed() -> None:
    rows = sweep_rows("quadtree", [10, 20, 30], FOUR, param="max_points", seeds=(2, 0, 1))
    table = prepare(pd.concat([rows.assign(terrain="sim_lan_2"), rows]))
    stats = measure_check(Optimum("lan", "quadtree", "max_points", "mhd_m", "low"), table).stats
    assert list(zip(stats["terrain"], stats["seed"], strict=True)) == [
        ("sim_lan_1", 0), ("sim_lan_1", 1), ("sim_lan_1", 2),
        ("sim_lan_2", 0), ("sim_lan_2", 1), ("sim_lan_2", 2)]


def test_an_optimum_needs_three_settings_and_reads_every_interior_one() -> None:
    optimum = Optimum("lan", "quadtree", "max_points", "mhd_m", "low")
    assert np.isnan(_values(optimum, _table([10, 20], {"mhd_m": [2.0, 1.0]}))).all()
    # three settings: the finest (2.0) minus the one interior setting (1.5)
    assert _values(optimum, _table([10, 20, 30], {"mhd_m": [2.0, 1.5, 3.0]})) == \
        pytest.approx([0.5, 0.5])
    # five: the best interior setting is the fourth (1.0), next to the coarsest
    five = _table([10, 20, 30, 40, 50], {"mhd_m": [2.0, 1.5, 1.4, 1.0, 3.0]})
    assert _values(optimum, five) == pytest.approx([1.0, 1.0])


def test_a_trend_over_the_larger_half_keeps_the_median_map() -> None:
    # five maps of 100..500 basis functions: the larger half is 300, 400, 500 (median kept),
    # whose MHDs 1, 2, 3 rise with max_points: rho = 1
    table = _table([10, 20, 30, 40, 50], {"mhd_m": [5.0, 4.0, 1.0, 2.0, 3.0]})
    trend = Trend("lan", "quadtree", "max_points", "mhd_m", +1, largest_half=True)
    assert _values(trend, table) == pytest.approx([1.0, 1.0])


def test_agreement_drops_missing_values_and_needs_two_distinct_values_each() -> None:
    check = Agreement("lan", "quadtree", "mhd_m", "completeness", min_rho=0.0)
    # a missing MHD is left out: the other three rank exactly against completeness -> rho -1
    table = _table([10, 20, 30, 40], {"mhd_m": [1.0, np.nan, 2.0, 3.0],
                                      "completeness": [0.9, 0.8, 0.7, 0.6]})
    assert _values(check, table) == pytest.approx([1.0, 1.0])  # 0 - (-1)
    # two distinct values among four settings still rank: tied ranks 1.5, 1.5, 3.5, 3.5
    table = _table([10, 20, 30, 40], {"mhd_m": [1.0, 1.0, 2.0, 2.0],
                                      "completeness": [0.9, 0.8, 0.7, 0.6]})
    rho = -np.sqrt(0.8)  # Pearson r of (1.5,1.5,3.5,3.5) with (4,3,2,1)
    assert _values(check, table) == pytest.approx([-rho, -rho])
    table = _table([10, 20, 30, 40], {"mhd_m": [1.0, 2.0, 3.0, 4.0],
                                      "completeness": [0.9, 0.9, 0.6, 0.6]})
    assert _values(check, table) == pytest.approx([-rho, -rho])
    table = _table([10, 20, 30, 40], {"mhd_m": [1.0, 2.0, 3.0, 4.0],
                                      "completeness": [0.9] * 4})
    assert np.isnan(_values(check, table)).all()


def _summary(values: list[float], agg: str = "cv") -> list[float]:
    return _values(Summary("lan", "quadtree", "mhd_m", agg),
                   _table(list(range(10, 10 * len(values) + 1, 10)), {"mhd_m": values}))


def test_a_coefficient_of_variation_needs_two_values_and_a_mean_off_zero() -> None:
    assert np.isnan(_summary([2.0])).all()
    # std of (1, 3) is 1 (population), mean 2: cv 0.5, and lower is better: 0 - 0.5
    assert _summary([1.0, 3.0]) == pytest.approx([-0.5, -0.5])
    assert np.isnan(_summary([-1.0, 1.0])).all()
    assert _summary([2.0], agg="median") == pytest.approx([-2.0, -2.0])


def _effect(rows: list[dict]) -> list[float]:
    table = pd.DataFrame(rows).assign(case="lan", terrain="sim_lan_1", seed=0, mapper="alte3d")
    return _values(Effect("lan", "alte3d", "mhd_m", "a", max_spread=1.0), table)


def test_an_effect_alone_is_the_range_of_its_level_means_over_their_mean() -> None:
    # levels 1.0 and 1.5: range 0.5 over the mean 1.25 is 0.4; the value is 1 - 0.4
    assert _effect([{"p_a": 1, "mhd_m": 1.0}, {"p_a": 2, "mhd_m": 1.5}]) == pytest.approx([0.6])
    assert np.isnan(_effect([{"p_a": 1, "mhd_m": 1.0}])).all()  # one level: no range
    # a mean under one is fine: 0.2 over 0.5
    assert _effect([{"p_a": 1, "mhd_m": 0.4}, {"p_a": 2, "mhd_m": 0.6}]) == pytest.approx([0.6])
    assert np.isnan(_effect([{"p_a": 1, "mhd_m": -1.0}, {"p_a": 2, "mhd_m": 1.0}])).all()


def test_an_effect_holds_a_two_level_parameter_fixed_and_skips_lone_settings() -> None:
    """mhd = 10 b + a: within each b, a moves MHD by 1; b = 3 has one level of a only."""
    rows = [{"p_a": a, "p_b": b, "mhd_m": 10.0 * b + a} for a in (1, 2) for b in (1, 2)]
    rows += [{"p_a": 2, "p_b": 2, "mhd_m": 22.0}, {"p_a": 1, "p_b": 3, "mhd_m": 31.0}]
    mean = (11 + 21 + 12 + 22 + 22 + 31) / 6
    assert _effect(rows) == pytest.approx([1.0 - 1.0 / mean])


def _timed(cost: bool) -> pd.DataFrame:
    rows = pd.concat([
        sweep_rows("quadtree", [10, 20, 30], {"elapsed_s": [1.0, 2.0, 3.0]}, param="max_points"),
        sweep_rows("octomap", [0.1, 0.2, 0.4], {"elapsed_s": [2.0, 1.0, 0.5]}, param="res")])
    rows["map_cpu_s"] = rows["elapsed_s"]
    if cost:  # costs fall while the times rise: what a check is judged on shows
        rows["cost"] = 1e6 / rows["elapsed_s"]
        rows["cost_unit"] = rows["mapper"].map({"quadtree": "cell updates",
                                                "octomap": "ray steps"})
    return prepare(rows)


def test_a_time_check_within_a_mapper_is_judged_on_its_cost_with_the_cpu_time_beside() -> None:
    trend = Trend("lan", "quadtree", "max_points", "elapsed_s", +1)
    found = measure_check(trend, _timed(cost=True))
    assert found.time == "cost"
    assert found.what == ("Spearman rho of mapping cost with max_points over Quadtree's maps, "
                          "times the stated sign (+1); cost in cell updates")
    assert found.stats["value"].tolist() == pytest.approx([-1.0] * 3)  # cost falls
    assert found.crosscheck is not None
    assert found.crosscheck.stats["value"].tolist() == pytest.approx([1.0] * 3)  # CPU rises
    assert found.crosscheck.what == ("Spearman rho of mapping CPU time [s] with max_points over "
                                     "Quadtree's maps, times the stated sign (+1)")


def test_a_time_check_without_costs_is_read_on_the_cpu_time() -> None:
    found = measure_check(Trend("lan", "quadtree", "max_points", "elapsed_s", +1),
                          _timed(cost=False))
    assert (found.time, found.crosscheck) == ("cpu", None)
    assert found.what.startswith("Spearman rho of mapping CPU time [s]")
    assert "cost in" not in found.what
    assert found.stats["value"].tolist() == pytest.approx([1.0] * 3)


def test_a_time_summary_names_the_cost_units_of_both_mappers() -> None:
    both = measure_check(Summary("lan", "quadtree", "elapsed_s", "median", other="octomap"),
                         _timed(cost=True))
    assert both.time == "cost" and both.what.endswith("; cost in cell updates, ray steps")
    alone = measure_check(Summary("lan", "quadtree", "elapsed_s", "median"), _timed(cost=True))
    assert alone.what.endswith("; cost in cell updates")


def test_a_check_on_anything_but_time_reads_no_time() -> None:
    found = measure_check(Trend("lan", "quadtree", "max_points", "mhd_m", +1),
                          _timed(cost=True).assign(mhd_m=lambda t: t["p_max_points"]))
    assert (found.time, found.crosscheck) == ("", None)


def _ablation(higher: bool = False, agg: str = "median") -> Contrast:
    return Contrast("lan", "quadtree", "mhd_m", agg, "coarse", higher_is_better=higher)


def _with_variant() -> pd.DataFrame:
    base = sweep_rows("quadtree", [10, 20, 30], FOUR, param="max_points")
    elsewhere = base.assign(terrain="sim_lan_2")
    variant = base.assign(mhd_m=lambda t: t["mhd_m"] + 1.0)
    return prepare(pd.concat([base.assign(variant="base"), elsewhere.assign(variant="base"),
                              variant.assign(variant="coarse")]))


@pytest.mark.parametrize(("check", "what", "unit"), [
    (_ablation(), "median of MHD [m] over Quadtree's settings, coarse minus the grid as "
     "specified", "m"),
    (_ablation(higher=True), "median of MHD [m] over Quadtree's settings, the grid as "
     "specified minus coarse", "m"),
    (_ablation(agg="cv"), "coefficient of variation of MHD [m] over Quadtree's settings, "
     "coarse minus the grid as specified", ""),
])
def test_a_contrast_says_which_grid_it_subtracts_from_which(check, what, unit) -> None:
    found = measure_check(check, _with_variant())
    assert (found.what, found.unit) == (what, unit)


def test_a_contrast_reads_only_the_variants_terrains() -> None:
    stats = measure_check(_ablation(), _with_variant()).stats
    assert set(stats["terrain"]) == {"sim_lan_1"}
    assert stats["value"].tolist() == pytest.approx([1.0] * 3)  # every MHD one metre more
    higher = measure_check(_ablation(higher=True), _with_variant()).stats
    assert higher["value"].tolist() == pytest.approx([-1.0] * 3)


def test_a_contrast_without_ablation_rows_says_so() -> None:
    with pytest.raises(NoDataError, match=r"^no ablation rows: variant 'coarse' needs the "
                       r"grid's variants$"):
        measure_check(_ablation(), _table([10, 20, 30], FOUR))
