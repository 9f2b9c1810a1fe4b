"""Determinism of the real report: same inputs and seeds give byte-identical tables."""

from __future__ import annotations

from pathlib import Path

import pytest

from alte.report.plan import PLAN, build_plan
from alte.report.runner import run_report

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.slow
def test_ch5_tables_byte_identical_across_runs(tmp_path: Path) -> None:
    if not (ROOT / "notebooks" / "ch5_analysis.ipynb").exists():
        pytest.skip("notebooks/ch5_analysis.ipynb absent")
    runs = build_plan(PLAN, quick=True, notebooks_dir=ROOT / "notebooks", only=["ch5_analysis"],
                      overrides={"FRAMES": 10, "ROWS": [0, 1], "OVERHANGS": False})
    reports = [run_report(runs, tmp_path / "reports", tmp_path / "data", quick=True,
                          progress=False) for _ in range(2)]
    assert all(not r.failed for r in reports), [r.error for r in reports[0].results]
    first, second = ([t.name for t in r.tables] for r in reports)
    assert first and first == second
    differ = [t.name for t, u in zip(reports[0].tables, reports[1].tables, strict=True)
              if t.read_bytes() != u.read_bytes()]
    assert not differ, f"tables differ between two identical runs: {differ}"
