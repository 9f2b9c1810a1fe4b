"""Two mappers compared: the reads behind each view, their time bounds and their words.

Expected values are worked out by hand; none is computed with the function under test.
"""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest
from support.tradeoff import sweep_rows

from alte.lab.studies.analysis.comparisons import measure_compare
from alte.lab.studies.analysis.measures import NoDataError
from alte.lab.studies.analysis.tradeoff import prepare
from alte.lab.studies.analysis.uncertainty import RUN_TIME_SPREAD
from alte.lab.studies.thesis.claims import Compare


def _pair(**columns: list[float]) -> pd.DataFrame:
    """Quadtree and 2D-ALTE over three settings, sizes 100, 200, 300 each; ``columns``
    name a column and its six values (quadtree's three, then 2D-ALTE's)."""
    rows = pd.concat([
        sweep_rows("quadtree", [10, 20, 30], {k: v[:3] for k, v in columns.items()},
                   param="max_points", seeds=(0, 1)),
        sweep_rows("alte2d", [1, 2, 3], {k: v[3:] for k, v in columns.items()},
                   param="max_res", seeds=(0, 1))])
    return prepare(rows)


def _at(**kw) -> Compare:
    return Compare("lan", "alte2d", "quadtree", **kw)


def test_a_time_read_at_equal_size_is_bounded_by_the_run_to_run_spread() -> None:
    table = _pair(elapsed_s=[1.0, 2.0, 4.0, 0.5, 1.0, 2.0]).assign(
        map_cpu_s=lambda t: t["elapsed_s"])
    found = measure_compare(_at(metric="elapsed_s", at="equal_size", levels=(200.0,)), table)
    # at 200 basis functions quadtree takes 2 s, 2D-ALTE 1 s: log(2) in 2D-ALTE's favour,
    # each time known within a factor exp(0.35): the bounds are 2 x 0.35 either side
    stats = found.stats
    assert stats["value"].tolist() == pytest.approx([np.log(2)] * 2)
    assert stats["low"].tolist() == pytest.approx([np.log(2) - 2 * RUN_TIME_SPREAD] * 2)
    assert stats["high"].tolist() == pytest.approx([np.log(2) + 2 * RUN_TIME_SPREAD] * 2)
    assert (found.time, found.read_from_times, found.level_name, found.level_kind) == (
        "cpu", True, "basis_functions", "size")


def test_a_fidelity_read_has_no_bounds_but_its_value() -> None:
    table = _pair(mhd_m=[3.0, 2.0, 1.0, 2.0, 1.0, 0.5])
    found = measure_compare(_at(metric="mhd_m", at="equal_size", levels=(200.0,)), table)
    assert found.stats["value"].tolist() == pytest.approx([1.0, 1.0])  # 2.0 - 1.0
    assert (found.stats["low"] == found.stats["value"]).all()
    assert (found.stats["high"] == found.stats["value"]).all()
    assert (found.time, found.read_from_times) == ("", False)


def test_equal_size_reads_on_the_size_column_it_names() -> None:
    table = _pair(mhd_m=[3.0, 2.0, 1.0, 2.0, 1.0, 0.5],
                  memory_bytes=[1000, 2000, 4000, 4000, 8000, 16000])
    found = measure_compare(_at(metric="mhd_m", at="equal_size", size="memory_bytes",
                                levels=(4000.0,)), table)
    # at 4000 bytes 2D-ALTE's MHD is 2.0, Quadtree's 1.0: Quadtree minus 2D-ALTE is -1
    assert found.stats["value"].tolist() == pytest.approx([-1.0, -1.0])
    assert found.what == "MHD [m], Quadtree minus 2D-ALTE at equal memory"
    assert found.level_name == "memory_bytes"


def test_equal_fidelity_reads_the_metric_it_names_at_the_fidelity_and_levels_given() -> None:
    table = _pair(hd_m=[4.0, 2.0, 1.0, 2.0, 1.0, 0.5],
                  memory_bytes=[1000, 2000, 4000, 4000, 8000, 16000])
    found = measure_compare(_at(metric="memory_bytes", at="equal_fidelity", fidelity="hd_m",
                                levels=(2.0,)), table)
    # HD 2.0: Quadtree at 2000 bytes, 2D-ALTE at 4000: log(2000 / 4000)
    assert found.stats["value"].tolist() == pytest.approx([-np.log(2)] * 2)
    assert found.stats["level"].tolist() == [2.0, 2.0]
    assert found.what == "memory [B], Quadtree / 2D-ALTE for equal HD [m]"
    assert (found.level_name, found.level_kind) == ("hd_m", "fidelity")


def test_a_time_for_equal_fidelity_reads_the_fidelity_and_levels_given() -> None:
    table = _pair(elapsed_s=[1.0, 2.0, 4.0, 1.0, 2.0, 4.0],
                  hd_m=[4.0, 2.0, 1.0, 2.0, 1.0, 0.5]).assign(map_cpu_s=lambda t: t["elapsed_s"])
    found = measure_compare(_at(metric="elapsed_s", at="equal_fidelity", fidelity="hd_m",
                                levels=(2.0,)), table)
    # HD 2.0: quadtree's least time is 2 s, 2D-ALTE's 1 s
    assert found.stats["value"].tolist() == pytest.approx([np.log(2)] * 2)
    assert found.stats["level"].tolist() == [2.0, 2.0]


@pytest.mark.parametrize(("where", "words", "level"), [
    ("thesis_point", "at the thesis' chosen settings", ""),
    ("rule", "at the settings the thesis' rule picks from our sweep", ""),
    ("equal_size", "at equal basis functions", "basis_functions"),
    ("equal_fidelity", "for equal MHD [m]", "mhd_m"),
])
def test_each_view_says_where_it_reads(where: str, words: str, level: str) -> None:
    table = _thesis_rows()
    found = measure_compare(_at(metric="occupied_cells", at=where), table)
    assert found.what == f"occupied cells, Quadtree / 2D-ALTE {words}"
    assert found.level_name == level


def _thesis_rows(terrains: tuple[str, ...] = ("sim_lan_1",)) -> pd.DataFrame:
    """Each mapper's thesis setting and one other, per terrain and seed."""
    rows = []
    for terrain in terrains:
        for seed in (1, 0):
            for mapper, settings in (
                    ("quadtree", [{"max_points": 150}, {"max_points": 50}]),
                    ("alte2d", [{"kappa": 0.05, "max_res": 4, "min_pts": 100},
                                {"kappa": 0.05, "max_res": 5, "min_pts": 100}])):
                for i, setting in enumerate(settings):
                    rows.append({"terrain": terrain, "mapper": mapper, "seed": seed,
                                 "params": json.dumps(setting), "basis_functions": 100 * (i + 1),
                                 "occupied_cells": (40 if mapper == "alte2d" else 80) * (i + 1),
                                 "memory_bytes": 1000, "elapsed_s": 1.0, "map_cpu_s": 1.0,
                                 "mhd_m": 1.0 / (i + 1), "hd_m": 5.0, "accuracy_mean_m": 0.1,
                                 "completeness": 0.9})
    return prepare(pd.DataFrame(rows))


def test_the_thesis_point_reads_each_seed_in_terrain_and_seed_order() -> None:
    table = _thesis_rows(("sim_lan_2", "sim_lan_1"))
    stats = measure_compare(_at(metric="occupied_cells", at="thesis_point"), table).stats
    assert list(zip(stats["terrain"], stats["seed"], strict=True)) == [
        ("sim_lan_1", 0), ("sim_lan_1", 1), ("sim_lan_2", 0), ("sim_lan_2", 1)]
    assert stats["value"].tolist() == pytest.approx([np.log(2)] * 4)  # 80 / 40 cells


def test_the_thesis_point_names_a_mapper_without_one_and_a_missing_setting() -> None:
    table = _thesis_rows()
    other = table.assign(mapper=table["mapper"].replace({"alte2d": "nope"}))
    with pytest.raises(NoDataError, match=r"^the thesis chose no nope map$"):
        measure_compare(Compare("lan", "nope", "quadtree", "mhd_m", "thesis_point"), other)
    lacking = table[~table["params"].str.contains('"max_res": 4')]
    with pytest.raises(NoDataError, match=r"^the table lacks the thesis' setting alte2d "
                       r"kappa=0\.05, max_res=4, min_pts=100$"):
        measure_compare(_at(metric="mhd_m", at="thesis_point"), lacking)


def test_the_rule_skips_a_seed_it_cannot_read_but_not_the_ones_after() -> None:
    table = _thesis_rows()
    # seed 0 of 2D-ALTE has no MHD at all (a criterion of the rule): that seed goes
    gap = (table["mapper"] == "alte2d") & (table["seed"] == 0)
    stats = measure_compare(_at(metric="occupied_cells", at="rule"),
                            table.assign(mhd_m=table["mhd_m"].mask(gap))).stats
    assert stats["seed"].tolist() == [1]


def test_the_rule_reads_a_seed_where_one_map_has_every_criterion() -> None:
    table = _thesis_rows()
    # one 2D-ALTE map per seed lacks its MHD: the other still has every criterion
    gap = (table["mapper"] == "alte2d") & (table["basis_functions"] == 200)
    stats = measure_compare(_at(metric="occupied_cells", at="rule"),
                            table.assign(mhd_m=table["mhd_m"].mask(gap))).stats
    assert stats["seed"].tolist() == [0, 1]


def test_the_rule_reading_no_seed_at_all_says_so() -> None:
    table = _thesis_rows()
    with pytest.raises(NoDataError, match="2D-ALTE and Quadtree share no terrain"):
        measure_compare(_at(metric="occupied_cells", at="rule"),
                        table.assign(mhd_m=table["mhd_m"].mask(table["mapper"] == "alte2d")))
