"""The documentation site, built with ``make docs``'s flags, then checked.

``make test`` builds it once (``site``, into a temporary folder: parallel-safe beside
``make docs``) with warnings as errors and the tutorials shown unexecuted
(``ALTE_DOCS_TUTORIALS=skip``; every other page as usual, the results pages computing
their tables): links and anchors, the reference's coverage of the command line and of
every public module, the settings tables, the results pages, the README, and the site as
a browser shows it. The tutorials' execution (a minute or two of CPU) is ``make
check-full``'s: marked ``full``, on a second build (``executed_site``) that runs them.
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import re
import subprocess
import sys
from html.parser import HTMLParser
from pathlib import Path
from urllib.parse import unquote, urlsplit

import pytest
from support.browser import browser_logs, chromium

from alte.cli import COMMANDS, full_parser
from alte.paths import REPO_ROOT, realdata_dir

DOCS = REPO_ROOT / "docs"
TUTORIALS = sorted((DOCS / "tutorials").glob("*.ipynb"))
NEEDS_REAL = {"map-a-terrain-tile", "compare-mappers"}  # conf.py: REAL_TUTORIALS


def _extension():  # the docs' own Sphinx extension (docs/_ext), for its module finder
    spec = importlib.util.spec_from_file_location("alte_docs", DOCS / "_ext" / "alte_docs.py")
    assert spec and spec.loader
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _build(out: Path, **env: str) -> Path:
    """The site built into ``out`` with warnings as errors (``make docs``'s flags)."""
    given = os.environ.get("ALTE_DOCS_SITE")
    if given:
        return Path(given).resolve()
    env = {**os.environ, "PYTHONWARNINGS": "ignore::DeprecationWarning", **env}
    done = subprocess.run(
        [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-E", "-q", "-b", "html",
         str(DOCS), str(out)], capture_output=True, text=True, env=env, check=False)
    problems = [line for line in done.stderr.splitlines()
                if "WARNING" in line or "ERROR" in line or "Error" in line]
    problems = [p for p in problems if "IPKernelApp" not in p]  # the kernel's TCP notice
    assert done.returncode == 0 and not problems, done.stderr[-6000:]
    return out


@pytest.fixture(scope="module")
def site(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The site with the tutorials unexecuted (``make test``). ``ALTE_DOCS_SITE=FOLDER``
    checks a site built there instead (``make docs`` then ``ALTE_DOCS_SITE=docs/_build/html
    pytest tests/docs``: the checks without the build)."""
    return _build(tmp_path_factory.mktemp("site") / "html", ALTE_DOCS_TUTORIALS="skip")


@pytest.fixture(scope="module")
def executed_site(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The site with every tutorial executed, as ``make docs`` builds it."""
    return _build(tmp_path_factory.mktemp("executed") / "html", ALTE_DOCS_TUTORIALS="run")


class _Links(HTMLParser):
    """Every href and src of a page, and the ids it defines."""

    def __init__(self) -> None:
        super().__init__()
        self.links: list[str] = []
        self.ids: set[str] = set()

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        for name, value in attrs:
            if value is None:
                continue
            if name in ("href", "src"):
                self.links.append(value)
            elif name == "id":
                self.ids.add(value)


def _parse(page: Path) -> _Links:
    found = _Links()
    found.feed(page.read_text(errors="replace"))
    return found


def _text(page: Path) -> str:
    return re.sub(r"\s+", " ", re.sub(r"<[^>]+>", " ", page.read_text()))


def test_every_internal_link_and_anchor_resolves(site: Path) -> None:
    pages = {p: _parse(p) for p in site.rglob("*.html")
             if not {"_static", "_sources"} & set(p.relative_to(site).parts)}  # theme assets
    broken = []
    for page, found in pages.items():
        for link in found.links:
            parts = urlsplit(link)
            if parts.scheme or parts.netloc or link.startswith(("mailto:", "javascript:")):
                continue
            target = (page.parent / unquote(parts.path)).resolve() if parts.path else page
            if not target.exists():
                broken.append(f"{page.relative_to(site)}: {link}")
            elif parts.fragment and target.suffix == ".html":
                ids = pages[target].ids if target in pages else _parse(target).ids
                if unquote(parts.fragment) not in ids:
                    broken.append(f"{page.relative_to(site)}: {link} (no such anchor)")
    assert broken == []


def test_the_link_check_can_fail(tmp_path: Path) -> None:
    (tmp_path / "a.html").write_text('<a href="b.html#x">b</a><a href="c.html">c</a>')
    (tmp_path / "b.html").write_text('<p id="y">b</p>')
    with pytest.raises(AssertionError, match="no such anchor"):
        test_every_internal_link_and_anchor_resolves(tmp_path)


def _options(parser: argparse.ArgumentParser) -> list[str]:
    return [s for a in parser._actions for s in a.option_strings if s.startswith("--")]


def test_every_command_and_option_is_in_the_cli_reference(site: Path) -> None:
    text = _text(site / "reference" / "cli.html")
    parser = full_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    missing = [name for name in COMMANDS if f"alte {name}" not in text]
    missing += [f"alte {name} {option}" for name, child in sub.choices.items()
                for option in _options(child) if option not in text]
    assert missing == []


def test_every_public_module_is_in_the_api_reference(site: Path) -> None:
    from sphinx.util.inventory import InventoryFile

    with (site / "objects.inv").open("rb") as handle:
        inventory = InventoryFile.load(handle, "", lambda *parts: "/".join(parts))
    documented = set(inventory.get("py:module", {}))
    modules = _extension().public_modules()
    assert len(modules) > 150  # the finder sees the whole package
    assert sorted(set(modules) - documented) == []


def test_settings_tables_list_every_mapper_setting(site: Path) -> None:
    from alte.mappers import registry

    page = (site / "reference" / "settings.html").read_text()
    text = _text(site / "reference" / "settings.html")
    mappers = registry.classes()  # the thesis' four and the installed plugins
    missing = [f"{cls.name}.{field}" for cls in mappers
               for field in cls.Settings.names() if field not in text]
    assert missing == [] and "gyro_noise" in text and "imu_hz" in text
    assert page.count("<table") >= len(mappers) + 9  # rendered tables, not reST as text
    assert "list-table" not in text and ":class:" not in text


@pytest.mark.parametrize("notebook", [p.stem for p in TUTORIALS])
def test_tutorial_keeps_no_outputs_in_git_and_is_on_the_site(site: Path, notebook: str) -> None:
    source = (DOCS / "tutorials" / f"{notebook}.ipynb").read_text()
    assert '"outputs": []' in source and '"output_type"' not in source  # stripped in git
    page = (site / "tutorials" / f"{notebook}.html").read_text()
    assert page.count('class="cell_input') >= 3 and "Traceback" not in page


@pytest.mark.full
@pytest.mark.parametrize("notebook", [p.stem for p in TUTORIALS])
def test_tutorial_ran_on_the_site(executed_site: Path, notebook: str) -> None:
    if notebook in NEEDS_REAL and not realdata_dir().is_dir():
        pytest.skip(f"{notebook} needs ../shared/realdata (absent: shown unexecuted)")
    page = (executed_site / "tutorials" / f"{notebook}.html").read_text()
    assert page.count('class="cell_output') >= 3
    assert "Traceback" not in page and "output traceback" not in page
    assert "<img" in page  # every tutorial draws at least one figure


def test_real_terrain_results_are_read_from_the_committed_evidence(site: Path) -> None:
    import pandas as pd

    evidence = pd.read_csv(REPO_ROOT / "notebooks" / "realterrain" / "realterrain_fronts.csv")
    page = (site / "results" / "real-terrain.html").read_text()
    text = _text(site / "results" / "real-terrain.html")
    assert [t for t in sorted(set(evidence["terrain"])) if t not in text] == []
    assert [c for c in sorted(set(evidence["terrain_class"])) if c not in text] == []
    assert page.count("<table") >= 5 and "holds" in text and "does not hold" in text
    assert "cell_input" not in page  # the computing code is hidden
    assert "Traceback" not in page and page.count("<img") >= 1


def test_results_pages_date_every_figure_and_name_their_command(site: Path) -> None:
    pages = sorted(p for p in (site / "results").glob("*.html") if p.name != "index.html")
    assert len(pages) == len(list((DOCS / "results").glob("*.md"))) - 1
    for page in pages:
        text = _text(page)
        assert re.search(r"20\d\d-\d\d-\d\d", text), f"{page.name}: no date"
        assert re.search(r"\b(alte|make|python) [a-z-]+", text), f"{page.name}: no command"
        assert "list-table" not in text  # the generated tables rendered


def test_the_readme_is_short_and_points_at_the_site() -> None:
    readme = (REPO_ROOT / "README.md").read_text()
    assert len(readme.splitlines()) <= 150
    assert "make docs" in readme and "docs/" in readme
    linked = re.findall(r"\]\((?!https?:)([^)#]+)", readme)
    assert [link for link in linked if not (REPO_ROOT / link).exists()] == []


def _figures(driver: object) -> list[int]:
    return driver.execute_script(  # type: ignore[attr-defined]
        "return Array.from(document.querySelectorAll('.cell_output img'))"
        ".map(i => i.complete ? i.naturalWidth : 0)")


def test_the_site_in_a_browser_shows_its_navigation_and_a_figure(
        site: Path, tmp_path: Path) -> None:
    with chromium(tmp_path) as driver:
        driver.get((site / "index.html").as_uri())
        nav = driver.execute_script(
            "return Array.from(document.querySelectorAll('.navbar-nav a.nav-link'))"
            ".map(a => a.textContent.trim())")
        assert {"Getting started", "Tutorials", "How-to guides", "Explanation",
                "Reference"} <= set(nav)
        diagram = driver.execute_script(
            "const i = document.querySelector('img[src$=\"pipeline.svg\"]');"
            "return i && i.complete ? i.naturalWidth : 0")
        assert diagram > 0
        driver.get((site / "results" / "real-terrain.html").as_uri())
        figures = _figures(driver)
        assert figures and min(figures) > 100  # rendered, not broken
        sidebar = driver.execute_script(
            "return Array.from(document.querySelectorAll('.bd-sidebar-primary a'))"
            ".map(a => a.textContent.trim())")
        assert "Results: real terrain" in sidebar
        assert browser_logs(driver) == []
        driver.get((site / "tutorials" / "write-a-mapper.html").as_uri())
        sidebar = driver.execute_script(
            "return Array.from(document.querySelectorAll('.bd-sidebar-primary a'))"
            ".map(a => a.textContent.trim())")
        assert {"Compare mappers on your data", "Write your own mapper"} <= set(sidebar)
        assert browser_logs(driver) == []
        shot = tmp_path / "results.png"
        assert driver.save_screenshot(str(shot)) and shot.stat().st_size > 10_000


@pytest.mark.full
def test_the_executed_tutorials_show_their_figures_in_a_browser(
        executed_site: Path, tmp_path: Path) -> None:
    with chromium(tmp_path) as driver:
        for page in ("map-your-bag", "write-a-mapper"):
            driver.get((executed_site / "tutorials" / f"{page}.html").as_uri())
            figures = _figures(driver)
            assert figures and min(figures) > 100, page  # rendered, not broken
            assert browser_logs(driver) == []
