"""The refactor check (tests/compare_reports.py) passes time readings and catches the rest."""

from __future__ import annotations

import pandas as pd
from compare_reports import compare


def _write(folder, claims, fidelity):
    folder.mkdir()
    pd.DataFrame(claims).to_csv(folder / "claims.csv", index=False)
    pd.DataFrame(fidelity).to_csv(folder / "equal_fidelity.csv", index=False)


def test_time_readings_pass_and_a_verdict_or_a_size_fails(tmp_path, capsys):
    claims = {"id": ["a", "b"], "verdict": ["holds", "depends"], "evidence": ["1 s", "x"],
              "elapsed_s": [1.0, 2.0]}
    fidelity = {"metric": ["basis_functions", "map_cpu_s"], "mean": [10.0, 0.5]}
    _write(tmp_path / "before", claims, fidelity)
    _write(tmp_path / "timed", {**claims, "evidence": ["2 s", "x"], "elapsed_s": [3.0, 2.0]},
           {**fidelity, "mean": [10.0, 0.7]})
    _write(tmp_path / "verdict", {**claims, "verdict": ["holds", "holds"]}, fidelity)
    _write(tmp_path / "size", claims, {**fidelity, "mean": [11.0, 0.5]})
    assert compare(tmp_path / "before", tmp_path / "timed") == 0
    assert "time readings equal_fidelity.csv: mean" in capsys.readouterr().out
    assert compare(tmp_path / "before", tmp_path / "verdict") == 1
    assert "DIFFER claims.csv: verdict" in capsys.readouterr().out
    assert compare(tmp_path / "before", tmp_path / "size") == 1
    assert "DIFFER equal_fidelity.csv: mean" in capsys.readouterr().out
