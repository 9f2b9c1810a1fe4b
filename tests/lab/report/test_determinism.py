"""Determinism of the real report: same inputs and seeds give identical tables.

Timing columns (``elapsed_*``, ``map_cpu_*``, ``time_repeats`` and the rule's score on
the readings) are measurements of the machine, not of the inputs, so they are removed
before comparing. The tables whose *chosen row* depends on
measured time through the thesis' comparison rule (5.1-5.4, 5.10, 5.11) are not
compared: their rule is a pure function of its inputs (tested in tests/test_analysis.py).
"""

from __future__ import annotations

import io
from pathlib import Path

import pandas as pd
import pytest

from alte.lab.report.plan import PLAN, build_plan
from alte.lab.report.runner import run_report
from alte.paths import REPO_ROOT

ROOT = REPO_ROOT
#: Tables whose content does not depend on which row a timing-based rule picked.
TIMING_FREE = {"table_5_5.csv", "table_5_6.csv", "table_5_7.csv", "table_5_8.csv",
               "table_5_9.csv", "table_5_12.csv", "tradeoff.csv", "tradeoff_variants.csv"}
#: The trade-off grid the runs sweep.
GRID = Path(__file__).with_name("determinism.yaml")


def _without_timing(path: Path) -> bytes:
    frame = pd.read_csv(path)
    timing = [c for c in frame.columns if not c.startswith("thesis_") and (
        "elapsed" in c or c.startswith("map_cpu") or c in ("time_repeats", "rule_score"))]
    out = io.StringIO()
    frame.drop(columns=timing).to_csv(out, index=False)
    return out.getvalue().encode()


@pytest.mark.full
@pytest.mark.slow
def test_ch5_tables_identical_across_runs_but_for_timing(tmp_path: Path) -> None:
    if not (ROOT / "notebooks" / "ch5_analysis.ipynb").exists():
        pytest.skip("notebooks/ch5_analysis.ipynb absent")
    # 4 scans everywhere (the sweeps' terrains are then the grid's, simulated once) and
    # GRID (tradeoff-small's structure, two settings per mapper grid: 56 runs, not 90)
    runs = build_plan(PLAN, quick=True, notebooks_dir=ROOT / "notebooks", only=["ch5_analysis"],
                      overrides={"FRAMES": 4, "ROWS": [0, 1], "OVERHANGS": False,
                                 "N_SAMPLES": 5000, "GRID_SPEC": str(GRID), "GRID_SEEDS": [0],
                                 "GRID_FRAMES": 4})
    reports = [run_report(runs, tmp_path / "reports", tmp_path / "data", quick=True,
                          progress=False) for _ in range(2)]
    assert all(not r.failed for r in reports), [r.error for r in reports[0].results]
    first, second = ([t.name for t in r.tables] for r in reports)
    assert first and first == second
    assert set(first) >= TIMING_FREE
    differ = [t.name for t, u in zip(reports[0].tables, reports[1].tables, strict=True)
              if t.name in TIMING_FREE and _without_timing(t) != _without_timing(u)]
    assert not differ, f"tables differ between two identical runs: {differ}"
