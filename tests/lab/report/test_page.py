"""The front page as data: sections, trade-off split, verdict counts, headline results."""

from __future__ import annotations

from pathlib import Path

from alte.lab.report.page import run_page

from .conftest import make_front_run


def test_run_page_model(tmp_path: Path) -> None:
    record = make_front_run(tmp_path)
    page = run_page(record, tmp_path, sorted((tmp_path / "tables").glob("*.csv")))
    assert page.failed == [("ch5_analysis", "failed")]
    assert page.summary.startswith("quick mode, started 2024-01-01") and "1 failed" in page.summary
    assert len(page.claims) == 12 and sum(n for _, n, _ in page.verdicts) == 12
    assert [Path(f.src).stem for f in page.tradeoff] == ["tradeoff_mhd", "equal_size_2d"]
    ch4, ch5 = page.sections
    assert [Path(f.src).stem for f in ch4.figures] == ["terrain", "cloud", "mystery"]
    assert [Path(f.src).stem for f in ch5.figures] == ["fig_5_2"]
    assert ("points", "120,161") in ch4.results and ("rows", "0, 1, 2") in ch4.results
    assert all(name not in ("maps", "sites", "table", "captions") for name, _ in ch4.results)
    assert ch5.error == "cell 2: ValueError: <boom>" and ch5.status == "failed"
    assert [t.title for t in page.key_tables] == ["Table 5.10: best 2D maps by the thesis' rule",
                                                  "MHD at equal size",
                                                  "Ablations: what moves the verdicts"]
    others = {t.title: t for t in page.tables}
    assert set(others) == {"extra.csv", "tradeoff.csv"}
    assert others["tradeoff.csv"].view is None and "rows" in others["tradeoff.csv"].caption
    assert others["extra.csv"].view is not None


def test_an_unreadable_table_is_named_not_fatal(tmp_path: Path) -> None:
    record = make_front_run(tmp_path)
    (tmp_path / "tables" / "broken.csv").write_text("")
    page = run_page(record, tmp_path, sorted((tmp_path / "tables").glob("*.csv")))
    broken = next(t for t in page.tables if t.title == "broken.csv")
    assert broken.view is None and broken.caption.startswith("unreadable: ")
