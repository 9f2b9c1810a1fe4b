"""Tests for alte.lab.studies.thesis.numbers: the transcribed tables are complete and consistent."""

from __future__ import annotations

import pytest

from alte.errors import ParameterError
from alte.lab.studies.thesis.numbers import (
    CASE_MAPPERS,
    CH4_PARAMS,
    COMPARISONS,
    SWEEPS,
    TERRAIN_CASE,
    mapper_params,
    qualitative_table,
    sweep_table,
)
from alte.sim import TERRAINS
from alte.sim.scenario import get_terrain


def test_every_terrain_has_the_parameters_of_its_case():
    assert list(TERRAIN_CASE) == list(TERRAINS)
    for terrain in TERRAINS:
        case = get_terrain(terrain).spec.case
        assert TERRAIN_CASE[terrain] == case
        assert set(CH4_PARAMS[terrain]) == set(CASE_MAPPERS[case])
    assert mapper_params("sim_lan_2")["quadtree"] == {"max_points": 25}
    assert mapper_params("exp_nav_1")["alte3d"] == {"max_res": 5, "min_pts": 5,
                                                    "min_pts_split": 10}


def test_mapper_params_are_copies():
    mapper_params("sim_lan_1")["alte2d"]["kappa"] = 99.0
    assert CH4_PARAMS["sim_lan_1"]["alte2d"]["kappa"] == 0.1


def test_sweep_tables_have_six_rows_and_thesis_columns():
    for number in SWEEPS:
        table = sweep_table(number)
        assert len(table) == 6
        assert {"thesis_elapsed_s", "thesis_basis_functions", "thesis_hd_m",
                "thesis_mhd_m"} <= set(table.columns)
        assert (table["thesis_hd_m"] >= table["thesis_mhd_m"]).all()
    assert sweep_table(8)["resolution"].tolist() == [1, 2, 3, 4, 5, 6]


def test_comparison_rows_match_tables_5_10_and_5_11():
    # Tables 5.10/5.11 print "MHD - HD" values that are HD - MHD of the chosen rows
    # (to 5e-4: the thesis rounds table 5.7 to 3 decimals).
    expected = {"quadtree": 4.2177, "alte2d": 4.2554, "octomap": 3.5472, "alte3d": 1.5424}
    for choices in COMPARISONS.values():
        for mapper, (table, row) in choices.items():
            _, _, _, hd, mhd = SWEEPS[table]["rows"][row]
            assert hd - mhd == pytest.approx(expected[mapper], abs=5e-4)


def test_qualitative_tables():
    table = qualitative_table(2)
    assert table.loc["octomap", "robustness"] == "High"
    assert table.loc["alte3d", "recursiveness"] == "Yes"


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda: mapper_params("moon"), "terrain 'moon' has no chapter 4 parameters"),
        (lambda: sweep_table(5), r"table 5.5 is not a sweep"),
        (lambda: qualitative_table(9), r"table 5.9 is not qualitative"),
    ],
)
def test_errors_name_the_culprit(call, match):
    with pytest.raises(ParameterError, match=match):
        call()
