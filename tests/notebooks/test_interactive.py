"""3D views: live (trame widget) in JupyterLab, a static PNG headless, same notebook code.

The kernel tests start a real IPython kernel (as JupyterLab, papermill and nbval
do) with the environment each of them gives it, run the code a notebook runs, and
inspect what the kernel publishes on iopub. No browser is attached here: the
browser test (test_jupyterlab.py) opens a chapter notebook in JupyterLab.
"""

from __future__ import annotations

import json
import os
import urllib.request
import warnings
from importlib import util
from pathlib import Path
from typing import Any

import pytest

from alte.lab import notebook
from alte.errors import ParameterError
from alte.paths import REPO_ROOT

WIDGET = "application/vnd.jupyter.widget-view+json"
LIVE = util.find_spec("trame_pyvista") is not None

_CODE = """
import json
import ipywidgets
import pyvista as pv
import alte.lab.notebook
from alte.lab.plot.figure import Caption
from alte.lab.plot.render import show, view

from IPython.display import display
from matplotlib.figure import Figure

mode = alte.lab.notebook.setup()
figure = Figure()
figure.add_subplot().plot([0, 1], [1, 0])
display(figure)  # a 2D figure: always a PNG
sphere = view(Caption("Sphere", "A sphere."), window_size=(320, 240))
sphere.plotter.add_mesh(pv.Sphere())
show(sphere, {out!r}, "sphere")
views = [w for w in list(ipywidgets.Widget.widgets.values()) if hasattr(w, "src")]
print("RESULT" + json.dumps({{"mode": mode, "views": [type(v).__module__ + "."
      + type(v).__name__ for v in views], "src": [v.src for v in views]}}))
"""


def _get(url: str) -> tuple[int, str]:
    with urllib.request.urlopen(url, timeout=30) as response:
        return response.status, response.read().decode("utf-8", "replace")


class KernelRun:
    """What a fresh python3 kernel published while running one piece of code."""

    def __init__(self, env: dict[str, str], cwd: Path = REPO_ROOT) -> None:
        pytest.importorskip("jupyter_client")
        self.env = {k: v for k, v in os.environ.items()
                    if k not in {"JPY_SESSION_NAME", "DISPLAY", "ALTE_RENDER"}} | env
        self.cwd = cwd
        self.shown: list[dict[str, Any]] = []
        self.printed: list[str] = []
        self.comms: list[str] = []
        self.pages: list[tuple[int, str]] = []

    def _hook(self, msg: dict[str, Any]) -> None:
        kind, content = msg["msg_type"], msg["content"]
        if kind == "display_data":
            self.shown.append(content["data"])
        elif kind == "stream":
            self.printed.append(content["text"])
        elif kind == "comm_open":
            self.comms.append(content["target_name"])
        elif kind == "error":
            self.printed.append("ERROR " + "\n".join(content["traceback"]))

    def run(self, code: str, fetch: bool = False) -> dict[str, Any]:
        """Execute ``code``; its ``RESULT{json}`` line; with ``fetch``, each view's page
        is fetched while the kernel (whose event loop runs the trame server) is up."""
        from jupyter_client.manager import start_new_kernel

        km, kc = start_new_kernel(kernel_name="python3", env=self.env, cwd=str(self.cwd))
        try:
            reply = kc.execute_interactive(code, timeout=180, output_hook=self._hook)
            text = "".join(self.printed)
            assert reply["content"]["status"] == "ok", text
            line = next((x for x in text.splitlines() if x.startswith("RESULT")), "RESULT{}")
            result: dict[str, Any] = json.loads(line.removeprefix("RESULT"))
            if fetch:
                self.pages = [_get(src) for src in result.get("src", [])]
        finally:
            kc.stop_channels()
            km.shutdown_kernel(now=True)
        return result


@pytest.mark.skipif(not LIVE, reason="pyvista[jupyter] absent")
def test_jupyterlab_kernel_shows_a_live_view_with_an_image_beside(tmp_path: Path) -> None:
    run = KernelRun({"JPY_SESSION_NAME": str(REPO_ROOT / "notebooks" / "ch4_terrain.ipynb")},
                    cwd=REPO_ROOT / "notebooks")
    result = run.run(_CODE.format(out=str(tmp_path)), fetch=True)
    assert result["mode"] == "interactive"
    assert result["views"] == ["trame_pyvista.jupyter.Widget"]
    ((status, page),) = run.pages  # the kernel's trame server serves the view
    assert result["src"][0].startswith("http://localhost:")
    assert status == 200 and "Application built with trame" in page
    figure, view = run.shown
    assert set(figure) == {"image/png", "text/plain"}
    assert WIDGET in view and view["image/png"].startswith("iVBORw0KGgo")  # base64 PNG
    assert (tmp_path / "figures" / "sphere.png").read_bytes()[:4] == b"\x89PNG"
    assert "PosixPath" not in "".join(run.printed)


@pytest.mark.parametrize("render", ["static", "interactive"])
def test_kernel_without_a_page_shows_pngs(tmp_path: Path, render: str) -> None:
    """papermill / nbval: no JupyterLab page, so even ``ALTE_RENDER=interactive``
    displays images that the saved notebook and its HTML keep."""
    run = KernelRun({"ALTE_RENDER": render, "MPLBACKEND": "Agg"})
    result = run.run(_CODE.format(out=str(tmp_path)))
    assert result["mode"] == "static"
    assert result["views"] == []
    assert [set(d) for d in run.shown] == [{"image/png", "text/plain"}] * 2
    assert (tmp_path / "figures" / "sphere.png").read_bytes()[:4] == b"\x89PNG"


_IMPORTS = "{first}\nimport open3d\nimport dash._jupyter as dj\nprint(dj._dash_comm is None)\n"


@pytest.mark.slow
@pytest.mark.parametrize("first, quiet", [("import alte.lab.notebook", True), ("", False)],
                         ids=["alte-first", "control"])
def test_importing_alte_notebook_first_keeps_the_dash_comm_and_banner_away(
        first: str, quiet: bool) -> None:
    """dash (imported by open3d) opens a ``dash`` comm nothing handles and open3d prints
    its WebVisualizer banner; both vanish when ``alte.lab.notebook`` is imported first."""
    run = KernelRun({"JPY_SESSION_NAME": "ch4_terrain.ipynb"})
    env = run.env
    env.pop("OPEN3D_DISABLE_WEB_VISUALIZER", None)
    run.run(_IMPORTS.format(first=first))
    printed = "".join(run.printed)
    assert ("dash" in run.comms) is not quiet, run.comms
    assert ("WebVisualizer" in printed) is not quiet, printed
    assert printed.strip().endswith(str(quiet))


def test_setup_works_from_the_repository_root(tmp_path: Path,
                                              monkeypatch: pytest.MonkeyPatch) -> None:
    """JupyterLab starts kernels in ``notebooks/``: ``DATA_DIR = "data"`` must still be
    the repository's ``data/``."""
    monkeypatch.chdir(tmp_path)
    notebook.setup("static")
    assert Path.cwd() == REPO_ROOT
    assert Path("data").resolve() == REPO_ROOT / "data"


def test_jupyterlab_session_selects_interactive(monkeypatch: pytest.MonkeyPatch) -> None:
    import pyvista as pv

    monkeypatch.delenv("ALTE_RENDER", raising=False)
    monkeypatch.setenv("JPY_SESSION_NAME", "/home/user/ch6_real_data.ipynb")
    old = pv.global_theme.jupyter_backend
    try:
        if LIVE:
            assert notebook.setup() == "interactive" and notebook.interactive()
            assert pv.global_theme.jupyter_backend == "trame"
        monkeypatch.setenv("ALTE_RENDER", "static")  # the variable wins over the session
        assert notebook.setup() == "static" and not notebook.interactive()
        monkeypatch.delenv("JPY_SESSION_NAME")  # no page: interactive is not possible
        assert notebook.setup("interactive") == "static" and not notebook.interactive()
    finally:
        notebook.setup("static")
        pv.set_jupyter_backend(old)


def test_missing_trame_falls_back_to_static(monkeypatch: pytest.MonkeyPatch) -> None:
    real = util.find_spec
    monkeypatch.setenv("JPY_SESSION_NAME", "ch4_terrain.ipynb")
    monkeypatch.setattr(util, "find_spec",
                        lambda name, *a: None if name == "trame_pyvista" else real(name, *a))
    with pytest.warns(UserWarning, match=r"need trame_pyvista .*pyvista\[jupyter\]"):
        assert notebook.setup("interactive") == "static"
    assert not notebook.interactive()


def test_bad_render_mode_is_a_parameter_error(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("ALTE_RENDER", "browser")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(ParameterError, match="render mode 'browser'"):
            notebook.setup()
