"""HTML pages: nbconvert output, a run's index and the top index."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from alte.errors import ReportError
from alte.report.html import notebook_to_html, run_index_html, top_index_html

from .conftest import BAD_BODY, BAD_PARAMS, make_notebook


def test_notebook_to_html(tmp_path: Path) -> None:
    nb = make_notebook(tmp_path / "bad.ipynb", BAD_PARAMS, BAD_BODY)
    out = notebook_to_html(nb, tmp_path / "bad.html")
    text = out.read_text()
    assert text.startswith("<!DOCTYPE html>") and "ValueError" in text
    assert oct(out.stat().st_mode & 0o777) == "0o644"


def test_notebook_to_html_unreadable(tmp_path: Path) -> None:
    (tmp_path / "x.ipynb").write_text("{")
    with pytest.raises(ReportError, match=r"cannot convert .*x\.ipynb to HTML"):
        notebook_to_html(tmp_path / "x.ipynb", tmp_path / "x.html")
    assert not (tmp_path / "x.html").exists()


def _record() -> dict:
    runs = [{"name": "good", "status": "ok", "seconds": 1.25, "notebook": "good.ipynb",
             "html": "good.html", "error": None},
            {"name": "bad", "status": "failed", "seconds": 0.5, "notebook": "bad.failed.ipynb",
             "html": "bad.failed.html", "error": "cell 2: ValueError: <boom>"}]
    return {"mode": "quick", "started": "2024-01-01T00:00:00+00:00", "seconds": 2.0,
            "runs": runs, "problems": ["terrain exp_lan_2: no data"]}


def test_run_index_html(tmp_path: Path) -> None:
    (tmp_path / "good" / "figures").mkdir(parents=True)
    (tmp_path / "good" / "figures" / "map.png").write_bytes(b"png")
    (tmp_path / "good" / "results.json").write_text(json.dumps({"rmse": 0.125, "n": [1, 2]}))
    (tmp_path / "tables").mkdir()
    table = tmp_path / "tables" / "table_5_1.csv"
    table.write_text("mapper,MHD\nquadtree,0.5\n")
    page = run_index_html(_record(), tmp_path, [table])
    failed_at = page.index("<b>Failed:</b>")
    assert failed_at < page.index("<h2 id='good'")
    assert "<a href='#bad'>bad</a>: failed" in page[failed_at:page.index("<h2 id='good'")]
    assert "terrain exp_lan_2: no data" in page
    assert "ValueError: &lt;boom&gt;" in page
    assert "href='good.html'" in page and "href='bad.failed.ipynb'" in page
    assert "src='good/figures/map.png'" in page
    assert "<th>rmse</th><td>0.125</td>" in page and "[1, 2]" in page
    assert "<td>quadtree</td>" in page and "href='tables/table_5_1.csv'" in page
    assert "total wall time 2.0 s" in page and "<td>1.2</td>" in page


def test_top_index_html() -> None:
    finished = _record()
    page = top_index_html([("runs/b", None), ("runs/a", finished)], "latest")
    assert "url=latest/index.html" in page
    assert "runs/b/index.html" in page and "interrupted (unfinished)" in page
    assert "quick, 2 runs, 1 failed" in page
    assert "no finished report yet" in top_index_html([("runs/b", None)], None)
