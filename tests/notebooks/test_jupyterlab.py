"""A chapter notebook in JupyterLab, as a person opens it: headless Chromium on 127.0.0.1.

The test starts JupyterLab in the repository, opens ``notebooks/ch4_terrain.ipynb``
(its defaults are small: about 20 s of computing), runs it from the Run menu and
checks what the person sees: no dialog (JupyterLab's "Build Recommended" included),
no error in the browser console, a 3D view that shows the scene and turns when
dragged, no path printed by ``show()``; and that the run left no file beside the
notebooks (JupyterLab starts kernels in ``notebooks/``), rewrote nothing already in
``data/`` and left no process behind.
It skips, with the reason, where Chromium, selenium or trame is missing.
"""

from __future__ import annotations

import shutil
import subprocess
import time
from collections.abc import Callable
from dataclasses import dataclass
from importlib import util
from pathlib import Path
from typing import Any

import pytest
from support.browser import (
    browser_logs,
    changed_share,
    chromium,
    drag,
    element_pixels,
    is_blank,
    processes_naming,
)
from support.jupyterlab import Lab, jupyterlab

from alte.paths import REPO_ROOT

NOTEBOOK = "notebooks/ch4_terrain.ipynb"
FOLDER = REPO_ROOT / "notebooks"
CHECKPOINTS = FOLDER / ".ipynb_checkpoints"  # JupyterLab's own, ignored by git

pytestmark = [pytest.mark.slow, pytest.mark.skipif(
    util.find_spec("trame_pyvista") is None, reason="pyvista[jupyter] (trame) is not installed")]


def _data_files() -> dict[str, int]:
    """Files under the repository's ``data/`` and their modification times."""
    return {str(p.relative_to(REPO_ROOT)): p.stat().st_mtime_ns
            for p in (REPO_ROOT / "data").rglob("*") if p.is_file()}


def _beside_notebooks() -> tuple[set[str], str]:
    """Files under ``notebooks/`` (ignored ones too, JupyterLab's checkpoints aside) and
    what ``git status`` says of the folder."""
    files = {str(p.relative_to(FOLDER)) for p in FOLDER.rglob("*")
             if p.is_file() and CHECKPOINTS not in p.parents and "__pycache__" not in p.parts}
    git = shutil.which("git")
    status = subprocess.run([git, "status", "--porcelain", "--untracked-files=all", "--",
                             "notebooks"], cwd=REPO_ROOT, capture_output=True, text=True,
                            check=False).stdout if git else ""
    return files, status


@dataclass
class Page:
    """The notebook's page in JupyterLab, driven the way a person uses it."""

    lab: Lab
    driver: Any
    folder: Path  # a screenshot lands here when a wait fails

    def until(self, condition: Callable[[], Any], timeout: float, what: str) -> Any:
        """``condition()`` once truthy; fails with the page's state after ``timeout``."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            found = condition()
            if found:
                return found
            time.sleep(0.5)
        shot = self.folder / "failed.png"
        self.driver.save_screenshot(str(shot))
        pytest.fail(f"{what} after {timeout:.0f} s (screenshot {shot}); console: "
                    f"{browser_logs(self.driver)}; outputs:\n{self.outputs()[-3000:]}")

    def find(self, css: str) -> list[Any]:
        from selenium.webdriver.common.by import By

        return list(self.driver.find_elements(By.CSS_SELECTOR, css))

    def outputs(self) -> str:
        return "\n".join(e.text for e in self.find(".jp-OutputArea"))

    def run_all(self) -> None:
        """Run > Run All Cells once the kernel is up; wait until every code cell ran."""
        def ready() -> bool:  # before its kernel is connected, Run All asks for a kernel
            idle = [s for s in self.lab.api("/api/sessions") if s["path"] == NOTEBOOK
                    and s["kernel"]["execution_state"] == "idle"]
            bar = self.find("#jp-main-statusbar")
            return bool(idle) and bool(bar) and "| Idle" in bar[0].text

        def done() -> bool:
            prompts = [e.text.strip() for e in self.find(".jp-CodeCell .jp-InputArea-prompt")]
            return bool(prompts) and all(p[1:-2].isdigit() for p in prompts)  # "[12]:"

        self.until(ready, 90, "no idle kernel")
        next(e for e in self.find(".lm-MenuBar-itemLabel") if e.text == "Run").click()
        self.until(lambda: self.find('li.lm-Menu-item[data-command="runmenu:run-all"]'),
                   10, "no Run All Cells in the Run menu")[0].click()
        self.until(done, 180, "the notebook did not finish")

    def view(self) -> Any:
        """The first live 3D view (pyvista's trame iframe), scrolled into sight and drawn."""
        view = self.until(lambda: self.find(".jp-OutputArea iframe.pyvista"), 30, "no 3D view")[0]
        self.driver.execute_script("arguments[0].scrollIntoView({block: 'center'});", view)
        self.until(lambda: not is_blank(element_pixels(view)), 30, "the 3D view stays blank")
        return view

    def turns(self, view: Any) -> float:
        """Drag across ``view``; the share of its pixels that changed (waits for a redraw)."""
        before = element_pixels(view)
        drag(self.driver, view)
        deadline, share = time.monotonic() + 15, 0.0
        while time.monotonic() < deadline and share < 0.02:
            time.sleep(0.5)
            share = changed_share(before, element_pixels(view))
        return share

    def check(self) -> None:
        build = self.lab.api("/lab/api/build")
        assert build["status"] == "stable", (f"JupyterLab wants a build: {build['message']} "
                                             "(.ci/bootstrap removes dash's unbuilt extension)")
        self.run_all()
        view = self.view()
        share = self.turns(view)
        assert share >= 0.02, f"dragging changed {share:.1%} of the 3D view"
        outputs = self.outputs()
        assert ".png')" not in outputs, outputs  # show() prints no figure path
        assert "WebVisualizer" not in outputs, outputs
        dialogs = [e.text for e in self.find(".jp-Dialog")]
        assert not dialogs, dialogs  # "Build Recommended" among others
        assert browser_logs(self.driver) == []


@pytest.mark.full
def test_chapter_notebook_runs_and_turns_in_jupyterlab(tmp_path: Path) -> None:
    before, data = _beside_notebooks(), _data_files()
    had_checkpoints = CHECKPOINTS.exists()
    try:
        with jupyterlab(tmp_path, REPO_ROOT) as lab, chromium(tmp_path) as driver:
            driver.get(lab.url(NOTEBOOK))
            Page(lab, driver, tmp_path).check()
        log = lab.log_text()
    finally:
        if not had_checkpoints:
            shutil.rmtree(CHECKPOINTS, ignore_errors=True)
    assert _beside_notebooks() == before, "the notebook wrote beside the notebooks"
    now = _data_files()  # the kernel used the repository's data/ and re-simulated nothing
    assert {k: now.get(k) for k in data} == data
    assert "without encryption" not in log, log
    assert lab.process.returncode is not None
    deadline = time.monotonic() + 15  # kernels (trame servers inside) and Chromium end
    while processes_naming(tmp_path) and time.monotonic() < deadline:
        time.sleep(0.5)
    assert processes_naming(tmp_path) == []
