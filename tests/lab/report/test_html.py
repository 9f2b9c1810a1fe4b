"""HTML pages: nbconvert output, a run's front page (templates) and the top index."""

from __future__ import annotations

from html.parser import HTMLParser
from importlib.resources import files
from pathlib import Path

import pytest

from alte.errors import ReportError
from alte.lab.report.html import notebook_to_html, run_index_html, top_index_html

from .conftest import BAD_BODY, BAD_PARAMS, make_front_run, make_notebook


class _Text(HTMLParser):
    """Visible text of a page (not style or script) and every src/href."""

    def __init__(self) -> None:
        super().__init__()
        self.text: list[str] = []
        self.links: list[str] = []
        self._skip = 0

    def handle_starttag(self, tag, attrs):
        self._skip += tag in ("style", "script")
        self.links += [v for k, v in attrs if k in ("src", "href") and v]

    def handle_endtag(self, tag):
        self._skip -= tag in ("style", "script")

    def handle_data(self, data):
        if not self._skip:
            self.text.append(data)


def _parse(page: str) -> _Text:
    parser = _Text()
    parser.feed(page)
    return parser


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


@pytest.fixture(scope="module")
def front(tmp_path_factory: pytest.TempPathFactory) -> tuple[str, Path]:
    """The front page of one finished run, built once: the tests below only read it (and
    the folder its links point into), so they share the run's tables, figures and claims."""
    run_dir = tmp_path_factory.mktemp("front")
    record = make_front_run(run_dir)
    page = run_index_html(record, run_dir, sorted((run_dir / "tables").glob("*.csv")))
    return page, run_dir


def test_front_page_order_answer_first_then_claims_tradeoffs_tables_chapters(front) -> None:
    page, _ = front
    marks = ["<b>Failed:</b>", 'id="answer"', 'id="claims"', 'id="claims-landing"',
             'id="tradeoffs"', 'id="key-tables"', 'id="chapters"', 'id="tables"']
    at = [page.index(m) for m in marks]
    assert at == sorted(at)
    assert '<a href="#ch5_analysis">ch5_analysis</a>: failed' in page
    assert "terrain exp_lan_2: no data" in page
    assert "cell 2: ValueError: &lt;boom&gt;" in page


def test_claims_tables_show_quotes_verdicts_conditions_and_evidence_by_question(front) -> None:
    page, _ = front
    table = page[page.index('id="claims"'):page.index('id="tradeoffs"')]
    groups = table.count('<table class="claims">')
    assert 2 <= groups <= 6 and table.count("<tr>") == groups + 12
    assert "<h3 id=\"claims-landing\">Landing: are 2D-ALTE&#39;s maps better" in table
    assert table.count('<td class="condition">') == 12
    assert "<q>Adaptability: Quadtree Mid, 2D ALTE High</q>" in table
    assert '<span class="verdict holds">holds</span>' in table
    assert '<span class="verdict untested">not measurable</span>' in table
    assert "<details><summary>numbers</summary>" in table and "95% percentile-bootstrap" in table


def test_tradeoff_figures_and_key_tables_with_units_and_thesis_values(front) -> None:
    page, _ = front
    trade = page[page.index('id="tradeoffs"'):page.index('id="key-tables"')]
    assert trade.index("ch5_analysis/figures/tradeoff_mhd.png") < trade.index(
        "ch5_analysis/figures/equal_size_2d.png")
    assert "<b>MHD against map size</b>" in trade and "Pareto front" in trade
    keys = page[page.index('id="key-tables"'):page.index('id="chapters"')]
    assert "Table 5.10: best 2D maps by the thesis&#39; rule" in keys
    assert '<th colspan="2">MHD [m]</th>' in keys and '<th class="sub">thesis</th>' in keys
    assert "<td>Quadtree</td>" in keys and "<td>1,435</td><td>4,399</td>" in keys
    assert "memory" not in keys  # unpaired metrics stay in the CSV
    assert 'href="tables/table_5_10.csv"' in keys


def test_chapter_sections_caption_figures_and_show_only_scalar_results(front) -> None:
    page, _ = front
    chapters = page[page.index('id="chapters"'):page.index('id="tables"')]
    assert "<h3>Chapter 4: terrain sim_lan_1</h3>" in chapters
    assert '<h3 class="failed">Chapter 5: analysis</h3>' in chapters
    assert chapters.index("figures/terrain.png") < chapters.index("figures/cloud.png")
    assert "The simulated terrain sim_lan_1 and its control volume." in chapters
    assert "A caption the notebook wrote itself." in chapters
    assert 'href="ch4_sim_lan_1.html">executed notebook</a>' in chapters
    assert "<dt>points</dt><dd>120,161</dd>" in chapters and "<dd>0, 1, 2</dd>" in chapters
    results = chapters[chapters.index('<dl class="results">'):chapters.index("</dl>")]
    assert "<dt>terrain</dt><dd>sim_lan_1</dd>" in results
    assert "max_points" not in results and "sites" not in results and "table" not in results
    assert "tradeoff_mhd" not in chapters  # shown once, in the trade-off section


def test_no_raw_dicts_or_json_and_every_link_is_relative_and_exists(front) -> None:
    page, run_dir = front
    parsed = _parse(page)
    text = "".join(parsed.text)
    assert "{" not in text and "}" not in text and "': " not in text and '": ' not in text
    local = [link for link in parsed.links if not link.startswith(("#", "../../"))]
    assert local and all(not link.startswith(("/", "file:", "http")) for link in local)
    missing = [link for link in local if not (run_dir / link).exists()]
    assert not missing
    other = page[page.index('id="tables"'):]
    assert "extra.csv" in other and "b [m]" in other
    assert "tradeoff.csv" in other and "Too long to show here" in other


def test_run_without_claims_or_figures_says_so(tmp_path: Path) -> None:
    record = {"mode": "full", "started": "x", "seconds": 1.0, "problems": [],
              "runs": [{"name": "solo", "status": "ok", "seconds": 1.0}]}
    page = run_index_html(record, tmp_path, [])
    assert "This run has no claims table" in page
    assert "This run made no trade-off figures." in page
    assert "<h3>solo</h3>" in page


def test_top_index_html() -> None:
    finished = {"mode": "quick", "runs": [{"status": "ok"}, {"status": "failed"}]}
    page = top_index_html([("runs/b", None), ("runs/a", finished)], "latest")
    assert '<a href="latest/index.html"><b>Open the latest report</b></a>' in page
    assert '<a href="runs/b/index.html">b</a>' in page and "interrupted (unfinished)" in page
    assert "quick, 2 runs, 1 failed" in page and '<td class="failed">1</td>' in page
    assert page.index("runs/b/index.html") < page.index("runs/a/index.html")
    assert "no finished report yet" in top_index_html([("runs/b", None)], None)


def test_templates_ship_as_package_data() -> None:
    folder = files("alte.lab.report") / "templates"
    assert {"base.html.j2", "macros.html.j2", "run.html.j2", "top.html.j2"} <= {
        p.name for p in folder.iterdir()}
    pyproject = Path(__file__).resolve().parents[3] / "pyproject.toml"
    assert '"alte.lab.report" = ["templates/*.j2"]' in pyproject.read_text()
