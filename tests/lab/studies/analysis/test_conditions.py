"""Each "depends" read back into where the claim holds and where it does not."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pandas as pd
import pytest
from support.tradeoff import Curve, synthetic_tradeoff

from alte.lab.studies.analysis.conditions import (
    TIMES_UNDECIDED,
    condition,
    part_label,
    terrain_names,
)
from alte.lab.studies.analysis.evidence import evaluate, evaluate_all
from alte.lab.studies.analysis.evidence_tables import write_evidence
from alte.lab.studies.analysis.measures import NoDataError, measure_check
from alte.lab.studies.analysis.tradeoff import prepare
from alte.lab.studies.thesis.claims import AllOf, Claim, Compare, Contrast, Summary, Trend, claim

MHD_AT_SIZE = Compare("lan", "alte2d", "quadtree", "mhd_m", "equal_size")


def _claim(check) -> Claim:
    return Claim("test", "5.2.2 (Comparison)", "a quote", check)


def _split() -> pd.DataFrame:
    """2D-ALTE wins clearly on sim_lan_1 and loses clearly on sim_lan_2."""
    wins = synthetic_tradeoff({"alte2d": Curve(scale=0.5)}, terrains={
        "quadtree": ("sim_lan_1",), "alte2d": ("sim_lan_1",)})
    loses = synthetic_tradeoff({"alte2d": Curve(scale=2.0)}, terrains={
        "quadtree": ("sim_lan_2",), "alte2d": ("sim_lan_2",)})
    both = pd.concat([wins, loses], ignore_index=True)
    return both[both["mapper"].isin(["quadtree", "alte2d"])]


def test_a_terrain_split_names_where_it_holds_and_where_not_with_the_sizes():
    found = evaluate(_claim(MHD_AT_SIZE), _split())
    assert (found.verdict, found.depends_on) == ("depends", "terrain")
    text = condition(found)
    assert text.startswith("holds on sim_lan_1 at ") and " basis functions; " in text
    assert "does not hold on sim_lan_2 at " in text


def test_a_size_split_gives_the_levels_of_each_outcome():
    table = synthetic_tradeoff({"alte2d": Curve(scale=1.0, slope=0.1, noise=0.0),
                                "quadtree": Curve(scale=3**0.4, slope=0.5, noise=0.0)})
    check = Compare("lan", "alte2d", "quadtree", "mhd_m", "equal_size", levels=(1500, 8000))
    text = condition(evaluate(_claim(check), table))
    assert text == ("on sim_lan_1 holds at 1,500 basis functions, does not hold at 8,000 "
                    "basis functions; on sim_lan_2 holds at 1,500 basis functions, does not "
                    "hold at 8,000 basis functions")


def test_parts_are_named_and_a_verdict_that_does_not_depend_has_no_condition():
    table = synthetic_tradeoff({"alte2d": Curve(scale=0.5)})
    worse = Compare("lan", "quadtree", "alte2d", "mhd_m", "equal_size")
    found = evaluate(_claim(AllOf((MHD_AT_SIZE, worse))), table)
    assert found.verdict == "depends"
    assert condition(found) == (
        "MHD at equal size (2D-ALTE vs Quadtree): holds on the simulated terrains "
        f"({'sim_lan_1, sim_lan_2'}) at {_span(found, 1)} | MHD at equal size (Quadtree vs "
        f"2D-ALTE): does not hold on the simulated terrains (sim_lan_1, sim_lan_2) at "
        f"{_span(found, 2)}")
    assert condition(evaluate(_claim(MHD_AT_SIZE), table)) == ""


def _span(found, part: int) -> str:
    levels = found.cells.loc[found.cells["part"] == part, "level"]
    return f"{levels.min():,.0f}-{levels.max():,.0f} basis functions"


def test_labels_and_terrain_names():
    assert part_label(Trend("lan", "quadtree", "max_points", "mhd_m", 1)) == (
        "MHD with max_points (Quadtree)")
    assert part_label(Summary("nav", "octomap", "mhd_m", "cv", "alte3d"), pair=True) == (
        "spread of MHD (Octomap vs 3D-ALTE)")
    assert part_label(Contrast("nav", "alte3d", "mhd_m", "cv", "min_pts_per_leaf")) == (
        "spread of MHD against min_pts_per_leaf")
    assert terrain_names(["exp_nav_2", "exp_nav_1"]) == "the lab terrains (exp_nav_1, exp_nav_2)"
    assert terrain_names(["sim_lan_1", "exp_lan_1"]) == "exp_lan_1, sim_lan_1"
    assert terrain_names(["sim_nav_1", "sim_nav_2", "exp_nav_1", "exp_nav_2"]) == (
        "every navigation terrain")


def _variants(table: pd.DataFrame, cv: float) -> pd.DataFrame:
    """The base grid and a min_pts_per_leaf variant whose 3D-ALTE MHD spreads ``cv`` times
    as much about its mean."""
    mine = table[table["mapper"] == "alte3d"]
    mean = mine.groupby(["terrain", "seed"])["mhd_m"].transform("mean")
    other = mine.assign(mhd_m=mean + cv * (mine["mhd_m"] - mean),
                        params=[json.dumps({**json.loads(p), "occupancy_level": 0})
                                for p in mine["params"]])
    return pd.concat([table.assign(variant="base"), other.assign(variant="min_pts_per_leaf")],
                     ignore_index=True)


def test_a_contrast_reads_the_ablation_rows_and_lacks_data_without_them():
    table = synthetic_tradeoff()
    check = Contrast("nav", "alte3d", "mhd_m", "cv", "min_pts_per_leaf")
    assert evaluate(_claim(check), table).verdict == "no data"
    assert evaluate(_claim(check), table, variants=_variants(table, 2.0)).verdict == "holds"
    loses = evaluate(_claim(check), table, variants=_variants(table, 0.5))
    assert loses.verdict == "does not hold"
    assert "min_pts_per_leaf minus the grid as specified" in loses.evidence
    level = evaluate_all([claim("6-occupancy-level")], table, variants=_variants(table, 0.5))
    assert (level[0].verdict, level[0].depends_on) in {("depends", "metric"),
                                                       ("does not hold", "")}


def test_claims_csv_carries_the_condition_column(tmp_path):
    files = write_evidence(_split(), tmp_path, claims=[_claim(MHD_AT_SIZE)])
    out = pd.read_csv(files.claims, keep_default_na=False)
    assert list(out.columns[:7]) == ["claim", "section", "verdict", "evidence", "depends_on",
                                     "condition", "question"]
    assert out["condition"].iloc[0].startswith("holds on sim_lan_1")


def test_two_maps_that_read_the_same_on_every_seed_are_equal_not_undecided():
    table = synthetic_tradeoff({"alte2d": Curve(scale=0.5)})
    table["obstacle_precision"] = 1.0  # both perfect everywhere
    check = Compare("lan", "alte2d", "quadtree", "obstacle_precision", "equal_size",
                    higher_is_better=True)
    found = evaluate(_claim(check), table)
    assert found.verdict == "depends"
    assert condition(found).startswith("equal (no difference) on the simulated terrains")


def test_a_part_read_from_times_with_an_undecided_cell_names_no_terrain():
    found = evaluate(_claim(MHD_AT_SIZE), _split())
    cells = found.cells.copy()
    cells.loc[cells.index[0], "outcome"] = "inconclusive"
    timed = dataclasses.replace(found, cells=cells.assign(from_times=True))
    assert condition(timed) == TIMES_UNDECIDED
    # the same cells read from anything but times keep their terrains and sizes
    untimed = dataclasses.replace(found, cells=cells.assign(from_times=False))
    assert "sim_lan_2" in condition(untimed) and "undecided" in condition(untimed)


def _by_hand(values: pd.Series, agg: str) -> float:
    """Median or coefficient of variation (population std over mean), as the thesis' tables
    aggregate a mapper's settings."""
    data = values.to_numpy(float)
    return float(data.std() / data.mean()) if agg == "cv" else float(np.median(data))


@pytest.mark.parametrize(("agg", "higher", "text", "unit"), [
    ("cv", False, "coefficient of variation of MHD [m] over 3D-ALTE's settings, "
                  "min_pts_per_leaf minus the grid as specified", ""),
    ("median", True, "median of MHD [m] over 3D-ALTE's settings, the grid as specified minus "
                     "min_pts_per_leaf", "m"),
])
def test_a_contrast_is_the_variants_aggregate_minus_the_bases_per_terrain_and_seed(
        agg, higher, text, unit):
    table = synthetic_tradeoff()
    both = prepare(_variants(table, 2.0).assign(
        mhd_m=lambda t: t["mhd_m"] + 0.5 * (t["variant"] != "base")))
    found = measure_check(Contrast("nav", "alte3d", "mhd_m", agg, "min_pts_per_leaf",
                                   higher_is_better=higher), both)
    assert (found.what, found.unit) == (text, unit)
    mine = both[both["mapper"] == "alte3d"]
    for row in found.stats.itertuples():
        at = mine[(mine["terrain"] == row.terrain) & (mine["seed"] == row.seed)]
        base, other = (_by_hand(at.loc[at["variant"] == v, "mhd_m"], agg)
                       for v in ("base", "min_pts_per_leaf"))
        assert row.value == pytest.approx((base - other) if higher else (other - base))
    assert set(found.stats["terrain"]) == set(mine["terrain"])


def test_a_contrast_names_what_it_lacks():
    table = synthetic_tradeoff()
    elsewhere = _variants(table, 2.0).query("variant == 'base' or terrain != terrain")
    with pytest.raises(NoDataError, match=r"no 3D-ALTE rows of variant 'min_pts_per_leaf' on "
                                          r"the nav terrains"):
        measure_check(Contrast("nav", "alte3d", "mhd_m", "cv", "min_pts_per_leaf"),
                      prepare(elsewhere))
