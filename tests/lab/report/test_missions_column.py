"""The front page shows the committed whole-mission verdict beside each 20-scan verdict
(``claims_missions.csv``) and marks the claims whose verdicts differ; without that table
the claims table is as before."""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from alte.lab.report.html import run_index_html
from alte.lab.studies.missions import compare_verdicts

from .conftest import make_front_run


def _page(tmp_path: Path) -> str:
    record = make_front_run(tmp_path)
    return run_index_html(record, tmp_path, sorted((tmp_path / "tables").glob("*.csv")))


def test_whole_mission_column_and_marks(tmp_path: Path) -> None:
    record = make_front_run(tmp_path)
    tables = tmp_path / "tables"
    short = pd.read_csv(tables / "claims.csv", keep_default_na=False)
    whole = short.copy()
    whole.loc[0, "verdict"] = "does not hold" if short["verdict"][0] != "does not hold" \
        else "holds"
    whole.loc[0, "depends_on"] = "terrain (whole)"
    cells = pd.DataFrame({"id": [short["id"][0]] * 2, "terrain": ["sim_lan_1", "sim_nav_2"],
                          "outcome": ["holds", "does not hold"]})
    compare_verdicts(short, whole, None, cells).to_csv(tables / "claims_missions.csv",
                                                       index=False)
    page = run_index_html(record, tmp_path, sorted(tables.glob("*.csv")))
    table = page[page.index('id="whole-missions"'):page.index('id="tradeoffs"')]
    assert "<th>Whole missions</th>" in table and "1\nof 12 differ" in table
    assert table.count('<tr class="differs">') == 1 and table.count("&ne;") == 2
    assert "depends on: terrain (whole)" in table
    assert ("what moved: whole missions: sim_lan_1: 1 hold; sim_nav_2: 1 do not hold"
            in table) and table.count("what moved: ") == 1
    assert "claims_missions.csv" not in page[page.index('id="tables"'):]  # shown, not listed


def test_without_whole_missions_the_table_is_unchanged(tmp_path: Path) -> None:
    page = _page(tmp_path)
    assert 'id="whole-missions"' not in page and "Whole missions" not in page
