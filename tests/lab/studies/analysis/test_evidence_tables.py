"""Evidence tables: what ch5 writes for the front page, and ablations."""

from __future__ import annotations

import pandas as pd
from support.tradeoff import Curve, synthetic_tradeoff

from alte.lab.studies.analysis.evidence import CELL_COLUMNS, EvidenceSettings
from alte.lab.studies.analysis.evidence_tables import (
    CLAIMS_CSV_COLUMNS,
    ablation_table,
    comparison_tables,
    write_evidence,
)
from alte.lab.studies.thesis.claims import CLAIMS, claim


def test_ablation_shows_what_moves_when_free_space_is_not_counted():
    # 3D-ALTE a bit better: Octomap needs ~2x the basis functions for the same MHD, but
    # 70 % of Octomap's basis functions are free cells
    table = synthetic_tradeoff({"alte3d": Curve(scale=0.8)})
    size = claim("t5.4-size")
    out = ablation_table([size, claim("5.2.2-3d-mhd")], {
        "basis functions": (table, EvidenceSettings()),
        "occupied cells": (table, EvidenceSettings(size="occupied_cells"))})
    row = out.set_index("id").loc["t5.4-size"]
    assert row["basis functions"] == "holds" and row["occupied cells"] == "does not hold"
    assert row["moves"] == "occupied cells"
    assert out.set_index("id").at["5.2.2-3d-mhd", "moves"] == ""



def test_comparison_tables_read_both_cases_at_the_stated_sizes():
    table = synthetic_tradeoff({"alte2d": Curve(scale=0.5)})
    at_size, at_fidelity = comparison_tables(table)
    assert list(at_size.columns) == ["case", "terrain", "metric", "level", "mapper", "mean",
                                     "low", "high", "seeds"]
    assert set(at_size["case"]) == {"lan", "nav"}
    assert set(at_size["level"]) <= {1000.0, 5000.0, 20000.0}
    lan = at_size[(at_size["metric"] == "mhd_m") & (at_size["terrain"] == "sim_lan_1")]
    wide = lan.pivot_table(index="level", columns="mapper", values="mean")
    assert (wide["alte2d"] < wide["quadtree"]).all() and len(wide) == 3
    assert set(at_size.loc[at_size["case"] == "nav", "metric"]) == {
        "mhd_m", "accuracy_mean_m", "completeness"}  # no height RMSE for 3D maps
    assert set(at_fidelity["metric"]) == {"basis_functions", "memory_bytes", "elapsed_s",
                                          "map_cpu_s"}
    assert (at_fidelity["seeds"] == 3).all()


def test_comparison_tables_skip_a_case_without_both_mappers():
    table = synthetic_tradeoff().query("mapper != 'alte3d'")
    at_size, _ = comparison_tables(table)
    assert set(at_size["case"]) == {"lan"}
    empty, _ = comparison_tables(table.query("mapper == 'octomap'"))
    assert empty.empty and "mean" in empty.columns


def test_write_evidence_writes_the_six_tables(tmp_path):
    table = synthetic_tradeoff({"alte2d": Curve(scale=0.5)})
    files = write_evidence(table, tmp_path, claims=CLAIMS[:5])
    claims = pd.read_csv(files.claims)
    assert list(claims.columns) == CLAIMS_CSV_COLUMNS and len(claims) == 5
    assert list(pd.read_csv(files.cells).columns) == CELL_COLUMNS
    assert files.equal_size.name == "equal_size.csv" and files.equal_fidelity.exists()
    assert len(files.findings) == 5
    key = pd.read_csv(files.key_equal_size)
    assert list(key.columns) == ["case", "terrain", "basis_functions", "mapper", "mhd_m",
                                 "ci_low_m", "ci_high_m", "seeds"]
    assert set(key["basis_functions"]) <= {1000, 5000, 20000} and (key["seeds"] == 3).all()
    assert (key["ci_low_m"] <= key["mhd_m"]).all() and (key["mhd_m"] <= key["ci_high_m"]).all()
    fid = pd.read_csv(files.key_equal_fidelity)
    assert list(fid.columns[2:5]) == ["mhd_m", "mapper", "basis_functions"]
    assert "ci_low" in fid.columns and fid["basis_functions"].gt(0).all()
    again = write_evidence(table, tmp_path, claims=CLAIMS[:5], options=EvidenceSettings(seed=1))
    assert again.claims == files.claims
