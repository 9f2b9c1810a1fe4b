"""Tests for the chapter 5 qualitative tables (measured grades beside the thesis')."""

from __future__ import annotations

from alte.lab.studies.analysis.qualitative import Inputs, qualitative_table


def test_qualitative_table_marks_sources():
    best = {"octomap": {"size_octaves": 0.0, "hd_minus_mhd_m": 3.0, "basis_functions": 1000,
                        "free_truly_free_share": 0.97},
            "alte3d": {"size_octaves": 4.0, "hd_minus_mhd_m": 1.0, "basis_functions": 100,
                       "free_truly_free_share": float("nan")}}
    inputs = {m: Inputs(b, [0.4, 0.41, 0.39] if m == "octomap" else [0.2, 0.6], True)
              for m, b in best.items()}
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
