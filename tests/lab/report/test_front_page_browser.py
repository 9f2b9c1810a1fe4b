"""The front page in a real browser: figures load, the claims table is there."""

from __future__ import annotations

from pathlib import Path

from support.browser import browser_logs, chromium

from alte.lab.report.html import run_index_html

from .conftest import make_front_run

_BROKEN = ("return Array.from(document.images)"
           ".filter(i => !(i.complete && i.naturalWidth > 0))"
           ".map(i => i.getAttribute('src'))")


def _render(run_dir: Path) -> Path:
    record = make_front_run(run_dir)
    page = run_dir / "index.html"
    page.write_text(run_index_html(record, run_dir, sorted((run_dir / "tables").glob("*.csv"))))
    return page


def test_front_page_renders_with_every_figure_and_the_claims_table(tmp_path: Path) -> None:
    page = _render(tmp_path / "run")
    with chromium(tmp_path) as driver:
        driver.get(page.as_uri())
        driver.execute_script("return document.readyState")
        images = driver.execute_script("return document.images.length")
        assert images == 6
        assert driver.execute_script(_BROKEN) == []
        first = driver.execute_script(
            "return document.querySelector('h2').parentElement.id")
        assert first == "answer"  # the bottom line opens the page, before the claims
        answer = driver.execute_script(
            "return document.getElementById('answer').innerText")
        assert all(m in answer for m in ("Quadtree", "2D-ALTE", "Octomap", "3D-ALTE"))
        assert "height RMSE" in answer and "basis functions" in answer and " m [" in answer
        rows = driver.execute_script(
            "return document.querySelectorAll('#claims table.claims tbody tr').length")
        assert rows == 12
        groups = driver.execute_script(
            "return Array.from(document.querySelectorAll('#claims h3')).map(h => h.id)")
        assert groups[0] == "claims-landing" and len(groups) >= 2
        badges = driver.execute_script(
            "return Array.from(document.querySelectorAll('#claims table .verdict'))"
            ".map(b => getComputedStyle(b).backgroundColor)")
        assert len(set(badges)) >= 2  # verdicts are coloured
        keyed = driver.execute_script(
            "return Array.from(document.querySelectorAll('#key-tables h3'))"
            ".map(h => h.textContent)")
        assert keyed[:3] == ["Table 5.10: best 2D maps by the thesis' rule", "MHD at equal size",
                             "Ablations: what moves the verdicts"]
        headers = driver.execute_script(
            "return Array.from(document.querySelectorAll('#key-tables th'))"
            ".map(h => h.textContent)")
        assert {"MHD [m]", "ci low [m]", "ours", "thesis", "set b centers"} <= set(headers)
        text = driver.execute_script("return document.body.innerText")
        assert "{'" not in text and '{"' not in text  # no raw dicts or JSON
        assert browser_logs(driver) == []
        height = driver.execute_script("return document.body.scrollHeight")
        driver.set_window_size(1400, min(height, 8000))
        shot = tmp_path / "front_page.png"
        assert driver.save_screenshot(str(shot)) and shot.stat().st_size > 10_000


def test_a_missing_figure_is_caught(tmp_path: Path) -> None:
    page = _render(tmp_path / "run")
    (tmp_path / "run" / "ch4_sim_lan_1" / "figures" / "cloud.png").unlink()
    with chromium(tmp_path) as driver:
        driver.get(page.as_uri())
        assert driver.execute_script(_BROKEN) == ["ch4_sim_lan_1/figures/cloud.png"]
