"""The bottom line's choices and orders, on hand-made grids whose answers are known."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from alte.lab.studies.analysis.tradeoff import mapper_title
from alte.lab.studies.answer import (
    USES,
    Budget,
    bottom_line,
    budgets,
    candidates,
    choose,
    order,
)

LANDING, NAVIGATION = USES
#: mapper -> setting -> (basis functions, height RMSE, MHD, completeness)
SETTINGS = {
    "quadtree": {"A": (500, 0.30, 0.10, 0.9), "B": (3000, 0.20, 0.05, 0.9),
                 "S": (700, 0.05, 0.20, 0.3)},  # S: accurate but covers 30 %: never chosen
    "alte2d": {"C": (800, 0.25, 0.40, 0.9), "D": (8000, 0.10, 0.30, 0.9)},
}


def grid(settings=SETTINGS, terrains=("sim_lan_1", "sim_lan_2"), seeds=(0, 1, 2)) -> pd.DataFrame:
    """A landing grid: every setting on every terrain and seed, 1 % seeded noise."""
    rng = np.random.default_rng(0)
    rows = []
    for mapper, mine in settings.items():
        for name, (size, rmse, mhd, complete) in mine.items():
            for terrain in terrains:
                for seed in seeds:
                    wiggle = 1 + 0.01 * rng.normal()
                    rows.append({"terrain": terrain, "case": "lan", "mapper": mapper,
                                 "params": json.dumps({"setting": name}), "seed": seed,
                                 "basis_functions": size, "occupied_cells": size,
                                 "memory_bytes": 8 * size, "elapsed_s": size * 1e-5,
                                 "map_cpu_s": size * 1e-5, "frames": 10,
                                 "mhd_m": mhd * wiggle, "hd_m": 2.0,
                                 "accuracy_mean_m": rmse / 2, "completeness": complete,
                                 "height_rmse_m": rmse * wiggle,
                                 "obstacle_recall": 0.5 + rmse, "obstacle_precision": 1.0})
    return pd.DataFrame(rows)


def _choice(table: pd.DataFrame, budget: Budget):
    pool = candidates(table, LANDING, "simulated")
    return choose(pool, LANDING, "simulated", ("sim_lan_1", "sim_lan_2"), budget)


def test_a_size_budget_picks_the_best_truth_that_fits_and_names_the_rival():
    table = grid()
    small = _choice(table, Budget("size", 1000))
    assert (small.best.mapper, small.best.setting) == ("alte2d", "setting=C")
    assert (small.rival.mapper, small.rival.setting) == ("quadtree", "setting=A")
    assert small.decided  # 0.25 against 0.30 with 1 % noise
    assert small.best.truth.estimate == pytest.approx(0.25, rel=0.02)
    assert small.best.truth.low < 0.25 < small.best.truth.high or small.best.truth.seeds == 3
    assert (small.by_mhd.mapper, small.by_mhd.setting) == ("quadtree", "setting=A")
    middle = _choice(table, Budget("size", 5000))
    assert (middle.best.mapper, middle.best.setting) == ("quadtree", "setting=B")
    assert _choice(table, Budget("size", 20_000)).best.setting == "setting=D"
    assert _choice(table, Budget("size", 100)).best is None


def test_a_need_picks_the_smallest_map_meeting_it_everywhere():
    need = _choice(grid(), Budget("need", 0.22))
    assert (need.best.setting, need.best.size) == ("setting=B", 3000)
    assert need.rival.setting == "setting=D" and need.by_mhd is None


def test_time_budgets_and_the_need_sit_inside_the_candidates():
    pool = candidates(grid(), LANDING, "simulated")
    assert set(pool["params"].map(lambda p: json.loads(p)["setting"])) == {"A", "B", "C", "D"}
    found = budgets(pool, LANDING)
    assert [b.kind for b in found] == ["size"] * 3 + ["time", "time", "need"]
    # ms per scan: 1e-5 s per basis function over 10 scans: A 0.5, C 0.8, B 3, D 8; the
    # quartiles 0.725 and 4.25 to one digit; the need: the worst terrain's RMSE of the
    # best third (0.1, 0.2, 0.25, 0.3 -> 0.2)
    assert [b.limit for b in found[3:]] == [0.7, 4.0, 0.2]
    assert Budget("need", 0.2).text(LANDING) == "height RMSE <= 0.2 m"
    assert Budget("time", 2).text(LANDING) == "at most 2 ms per scan"


def test_a_changed_table_changes_the_choice():
    changed = {**SETTINGS, "alte2d": {**SETTINGS["alte2d"], "C": (800, 0.35, 0.40, 0.9)}}
    small = _choice(grid(changed), Budget("size", 1000))
    assert (small.best.mapper, small.best.setting) == ("quadtree", "setting=A")


def test_orders_count_the_equal_size_reads_each_mapper_wins():
    table = grid({"quadtree": {f"q{i}": (100 * 3**i, 0.3 / (i + 1), 0.1 / (i + 1), 0.9)
                               for i in range(5)},
                  "alte2d": {f"a{i}": (100 * 3**i, 0.2 / (i + 1), 0.2 / (i + 1), 0.9)
                             for i in range(5)}})
    mhd, truth = order(table, LANDING, "mhd_m"), order(table, LANDING, "height_rmse_m")
    assert mhd.reads == truth.reads == 6  # three sizes on two terrains
    assert mhd.leader == "quadtree" and mhd.leads == {"quadtree": 6, "alte2d": 0}
    assert truth.leader == "alte2d" and truth.undecided == 0
    assert truth.text().startswith("2D-ALTE on 6 of 6 reads (sim_lan_1, sim_lan_2)")
    line = bottom_line(table).uses[0]
    assert "MHD favours Quadtree, height RMSE" in line.disagreement
    assert bottom_line(table).uses[1].choices == []  # no navigation rows
    single = order(table[table["seed"] == 0], LANDING, "mhd_m")
    assert single.leader == "quadtree" and single.reads == 6  # one recording: no interval


def _fronts(first, second, terrains, case="lan"):
    """Two mappers' fronts (five sizes), the first's truth ``first`` x the second's."""
    pair = {"lan": ("quadtree", "alte2d"), "nav": ("octomap", "alte3d")}[case]
    settings = {pair[0]: {f"a{i}": (100 * 3**i, first / (i + 1), 0.1, 0.9) for i in range(5)},
                pair[1]: {f"b{i}": (100 * 3**i, second / (i + 1), 0.1, 0.9) for i in range(5)}}
    table = grid(settings, terrains)
    if case == "nav":
        table = table.assign(case="nav", accuracy_mean_m=table["height_rmse_m"])
    return table


def test_real_terrain_classes_say_where_the_built_in_answer_holds():
    from alte.lab.studies.answer.classes import class_checks

    builtin = _fronts(0.3, 0.2, ("sim_lan_1", "sim_lan_2"))  # 2D-ALTE leads
    agree = _fronts(0.3, 0.2, ("ign_farmland",)).assign(terrain_class="flat open",
                                                         evidence="flown")
    disagree = _fronts(0.2, 0.3, ("pyfor_forest",)).assign(terrain_class="flat under forest",
                                                           evidence="points")
    checks = class_checks(builtin, pd.concat([agree, disagree]), LANDING)
    assert [(c.terrain_class, c.evidence, c.verdict) for c in checks] == [
        ("flat open", "flown", "holds"), ("flat under forest", "points", "does not hold")]
    assert "flat open (ign_farmland; flown over the real surface" in checks[0].text()
    assert class_checks(builtin, None, LANDING) == []
    line = bottom_line(builtin, terrain=pd.concat([agree, disagree])).uses[0]
    assert [c.verdict for c in line.classes] == ["holds", "does not hold"]


def test_a_sequence_whose_landing_maps_are_metres_off_says_why_it_cannot_rank_them():
    builtin = _fronts(0.3, 0.2, ("sim_lan_1", "sim_lan_2"))
    far = _fronts(25.0, 21.5, ("balm_seq",)).query("seed == 0")  # best 4.3 m
    landing = bottom_line(builtin, far).uses[0]
    assert landing.real == []
    assert landing.real_why.startswith("balm_seq cannot rank landing maps: its best map is 4.")
    near = _fronts(0.3, 0.2, ("balm_seq",)).query("seed == 0")
    ranked = bottom_line(builtin, near).uses[0]
    assert ranked.real and not ranked.real_why


def test_a_completeness_need_picks_the_most_accurate_map_covering_that_much():
    table = _fronts(0.3, 0.2, ("sim_nav_1", "sim_nav_2"), case="nav")
    table.loc[table["mapper"] == "alte3d", "completeness"] = 0.6  # accurate, covers less
    pool = candidates(table, NAVIGATION, "simulated")
    found = budgets(pool, NAVIGATION, cover=(0.8,))
    # read off the candidates: the median (0.75) and the best third (0.9) of 0.6 and 0.9
    assert [b.limit for b in found if b.kind == "cover"] == [0.75, 0.8, 0.9]
    need = choose(pool, NAVIGATION, "simulated", ("sim_nav_1", "sim_nav_2"), Budget("cover", 0.8))
    assert need.best.mapper == "octomap" and need.rival is None
    loose = choose(pool, NAVIGATION, "simulated", ("sim_nav_1", "sim_nav_2"), Budget("cover", 0.6))
    assert loose.best.mapper == "alte3d"
    assert Budget("cover", 0.8).text(NAVIGATION) == "completeness >= 0.8 on every terrain"
    assert [b.kind for b in budgets(candidates(grid(), LANDING, "simulated"), LANDING)].count(
        "cover") == 0


#: The elevation map's title: its plugin's when installed (make bootstrap installs it).
ELEVATION = mapper_title("elevation")


def _with_challenger(calibrated: float) -> pd.DataFrame:
    """Quadtree and 2D-ALTE as in the orders test, and an elevation map (a 2D plugin) that
    beats both on sim_lan_1 and loses to both on sim_lan_2, claiming a height sigma whose
    2-sigma share is ``calibrated``; a 3D map in the same table is no challenger."""
    fronts = {"quadtree": 0.3, "alte2d": 0.2, "elevation": 0.25, "octomap": 0.2}
    table = grid({m: {f"{m}{i}": (100 * 3**i, k / (i + 1), k / (i + 1), 0.9)
                      for i in range(5)} for m, k in fronts.items()})
    table["dims"] = np.where(table["mapper"] == "octomap", 3, 2)
    elevation = table["mapper"] == "elevation"
    better = elevation & (table["terrain"] == "sim_lan_1")
    table.loc[better, "height_rmse_m"] *= 0.2
    table.loc[elevation & ~better, "height_rmse_m"] *= 1.3
    table["within_2sigma"] = np.where(elevation, calibrated, np.nan)
    table["sigma_mean_m"] = np.where(elevation, 0.01, np.nan)
    return table


def test_a_challenger_joins_the_candidates_and_is_read_terrain_by_terrain():
    answer = bottom_line(_with_challenger(0.9)).uses[0]
    assert answer.use.mappers == ("quadtree", "alte2d")
    assert {d.rival for d in answer.duels} == {"quadtree", "alte2d"}
    assert all(d.challenger == "elevation" for d in answer.duels)
    text = answer.duels[0].text()
    assert text == (f"{ELEVATION} against Quadtree, height RMSE at equal size: leads on "
                    "sim_lan_1 (3 of 3 reads); loses on sim_lan_2 (3 of 3)")
    assert any(c.best is not None and c.best.mapper == "elevation" for c in answer.choices)
    (calibration,) = answer.calibration
    assert calibration.median == 0.9 and calibration.maps == 30
    assert calibration.text().startswith(
        f"{ELEVATION} on the simulated terrains (sim_lan_1, sim_lan_2): the true height lies "
        "within 2 claimed sigma on 90.0 % of the mapped area (median of 30 maps")
    assert "over-confident" in calibration.text()
    assert "cautious" in bottom_line(_with_challenger(0.99)).uses[0].calibration[0].text()
    assert "): calibrated" in bottom_line(_with_challenger(0.95)).uses[0].calibration[0].text()


def test_without_a_dims_column_there_is_no_challenger():
    table = _with_challenger(0.9).drop(columns=["dims", "within_2sigma"])
    answer = bottom_line(table).uses[0]
    assert answer.duels == [] and answer.calibration == []


def test_a_challenger_is_read_per_class_of_real_terrain():
    """The real-terrain evidence with the challenger's rows: read against each of the
    thesis' two per class and kind of evidence, and its flown maps' calibration per class."""
    real = _with_challenger(0.9)
    real = real[real["mapper"] != "octomap"].assign(
        evidence="flown", terrain_class=lambda t: t["terrain"].map(
            {"sim_lan_1": "flat open", "sim_lan_2": "slope"}))
    answer = bottom_line(_with_challenger(0.9), terrain=real).uses[0]
    (vs_quadtree,) = [d for d in answer.duels if d.where and d.rival == "quadtree"]
    assert vs_quadtree.text() == (
        f"{ELEVATION} against Quadtree on real terrain, height RMSE at equal size: leads on "
        "flat open (flown) (3 of 3 reads); loses on slope (flown) (3 of 3)")
    classes = [c.group for c in answer.calibration]
    assert classes == ["simulated", "real flat open", "real slope"]
