"""Captions and chapter titles: registry, a notebook's own captions, field filling."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from alte.paths import REPO_ROOT
from alte.report.captions import CHAPTERS, FIGURES, caption, chapter_title
from alte.report.plan import PLAN

NOTEBOOKS = REPO_ROOT / "notebooks"
_SAVED = re.compile(r"""(?:save_figure|show)\([^,()]+,\s*OUT_DIR,\s*["']([\w.-]+)["']\)""")


def _saved_figures(path: Path) -> set[str]:
    cells = json.loads(path.read_text())["cells"]
    code = "\n".join("".join(c["source"]) for c in cells if c["cell_type"] == "code")
    return set(_SAVED.findall(code))


@pytest.mark.skipif(not NOTEBOOKS.is_dir(), reason="notebooks/ absent")
def test_every_figure_a_notebook_saves_by_name_has_a_caption():
    seen = {}
    for path in sorted(NOTEBOOKS.glob("*.ipynb")):
        names = _saved_figures(path)
        seen[path.stem] = names
        missing = names - set(FIGURES.get(path.stem, {}))
        assert not missing, f"{path.name}: add captions for {sorted(missing)} to FIGURES"
    assert sum(len(v) for v in seen.values()) >= 20


def test_every_planned_notebook_has_a_chapter_title():
    assert {Path(e.notebook).stem for e in PLAN} <= set(CHAPTERS)


def test_caption_precedence_and_fields():
    params = {"TERRAIN": "sim_lan_1"}
    assert caption("ch4_terrain", "cloud", params).text == (
        "The registered point cloud of sim_lan_1.")
    own = caption("ch4_terrain", "cloud", params, {"cloud": "Mine."})
    assert (own.title, own.text) == ("Registered cloud", "Mine.")
    unknown = caption("ch4_terrain", "odd_one", params, {"other": "x"})
    assert (unknown.title, unknown.text) == ("odd one", "(no caption)")
    assert caption("ch4_terrain", "cloud", {}).text == "The registered point cloud."
    assert caption("ch4_terrain", "terrain", {}).text == (
        "The simulated terrain and its control volume.")


def test_chapter_titles():
    assert chapter_title("ch4_terrain", "ch4_sim_nav_2", {"TERRAIN": "sim_nav_2"}) == (
        "Chapter 4: terrain sim_nav_2")
    assert chapter_title("ch2_test_benchmark", "ch2", {}) == (
        "Chapter 2: the test benchmark")
    assert chapter_title("custom", "my_run", {}) == "my run"
