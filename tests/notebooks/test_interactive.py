"""3D views: interactive (trame widget) in JupyterLab, a static PNG headless, same notebook code.

The kernel tests start a real IPython kernel (as JupyterLab does) with
``ALTE_RENDER`` set, run the code a notebook runs, and inspect what the kernel
publishes on iopub. No browser is attached: the widget is created and its trame
server answers HTTP, but nothing draws it (the websocket session and the
client-side rendering in a browser are not exercised).
"""

from __future__ import annotations

import json
import os
import urllib.request
import warnings
from importlib import util
from pathlib import Path

import pytest

from alte import notebook
from alte.errors import ParameterError
from alte.paths import REPO_ROOT

ROOT = REPO_ROOT
WIDGET = "application/vnd.jupyter.widget-view+json"

_CODE = """
import json
import ipywidgets
import pyvista as pv
import alte.notebook
from alte.plot.render import new_plotter, show

from IPython.display import display
from matplotlib.figure import Figure
from alte.paths import REPO_ROOT

mode = alte.notebook.setup()
figure = Figure()
figure.add_subplot().plot([0, 1], [1, 0])
display(figure)  # a 2D figure: always a PNG
plotter = new_plotter(window_size=(320, 240))
plotter.add_mesh(pv.Sphere())
path = show(plotter, {out!r}, "sphere")
views = [w for w in list(ipywidgets.Widget.widgets.values()) if hasattr(w, "src")]
print("RESULT" + json.dumps({{"mode": mode, "path": str(path), "views": [type(v).__module__ + "."
      + type(v).__name__ for v in views], "src": [v.src for v in views]}}))
"""


def _get(url: str) -> tuple[int, str]:
    with urllib.request.urlopen(url, timeout=30) as response:
        return response.status, response.read().decode("utf-8", "replace")


def _run_in_kernel(render: str, out: Path) -> tuple[dict, list[set[str]]]:
    """Run :data:`_CODE` in a fresh python3 kernel; (printed result, mime types displayed).

    While the kernel is still up (its event loop runs the trame server), each view's
    page is fetched from here: ``result["pages"]`` = (HTTP status, body) per view.
    """
    pytest.importorskip("jupyter_client")
    from jupyter_client.manager import start_new_kernel

    env = {k: v for k, v in os.environ.items() if k not in {"JPY_SESSION_NAME", "DISPLAY"}}
    env |= {"ALTE_RENDER": render, "MPLBACKEND": "Agg"}
    km, kc = start_new_kernel(kernel_name="python3", env=env, cwd=str(ROOT))
    shown: list[set[str]] = []
    printed: list[str] = []

    def hook(msg: dict) -> None:
        if msg["msg_type"] == "display_data":
            shown.append(set(msg["content"]["data"]))
        elif msg["msg_type"] == "stream" and msg["content"]["name"] == "stdout":
            printed.append(msg["content"]["text"])
        elif msg["msg_type"] == "error":
            printed.append("ERROR " + "\n".join(msg["content"]["traceback"]))

    try:
        reply = kc.execute_interactive(_CODE.format(out=str(out)), timeout=180, output_hook=hook)
        text = "".join(printed)
        assert reply["content"]["status"] == "ok", text
        line = next(x for x in text.splitlines() if x.startswith("RESULT"))
        result = json.loads(line.removeprefix("RESULT"))
        result["pages"] = [_get(src) for src in result["src"]]
    finally:
        kc.stop_channels()
        km.shutdown_kernel(now=True)
    return result, shown


@pytest.mark.skipif(util.find_spec("trame_pyvista") is None, reason="pyvista[jupyter] absent")
def test_interactive_kernel_shows_a_live_trame_widget(tmp_path: Path) -> None:
    result, shown = _run_in_kernel("interactive", tmp_path)
    assert result["mode"] == "interactive"
    assert result["views"] == ["trame_pyvista.jupyter.Widget"]
    ((status, page),) = result["pages"]  # the kernel's trame server serves the view
    assert result["src"][0].startswith("http://localhost:")
    assert status == 200 and "Application built with trame" in page
    figure, view = shown
    assert "image/png" in figure
    assert WIDGET in view and "image/png" not in view
    assert (tmp_path / "figures" / "sphere.png").read_bytes()[:4] == b"\x89PNG"


def test_static_kernel_shows_a_png(tmp_path: Path) -> None:
    result, shown = _run_in_kernel("static", tmp_path)
    assert result["mode"] == "static"
    assert result["views"] == [] and result["pages"] == []
    assert shown == [{"image/png", "text/plain"}] * 2  # the 2D figure, then the 3D view
    assert (tmp_path / "figures" / "sphere.png").read_bytes()[:4] == b"\x89PNG"


def test_jupyterlab_session_selects_interactive(monkeypatch: pytest.MonkeyPatch) -> None:
    import pyvista as pv

    monkeypatch.delenv("ALTE_RENDER", raising=False)
    monkeypatch.setenv("JPY_SESSION_NAME", "/home/user/ch6_real_data.ipynb")
    old = pv.global_theme.jupyter_backend
    try:
        if util.find_spec("trame_pyvista") is not None:
            assert notebook.setup() == "interactive" and notebook.interactive()
            assert pv.global_theme.jupyter_backend == "trame"
        monkeypatch.setenv("ALTE_RENDER", "static")  # the variable wins over the session
        assert notebook.setup() == "static" and not notebook.interactive()
    finally:
        notebook.setup("static")
        pv.set_jupyter_backend(old)


def test_missing_trame_falls_back_to_static(monkeypatch: pytest.MonkeyPatch) -> None:
    real = util.find_spec
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
