"""Helpers the chapter notebooks call, so that the notebooks hold no logic.

``setup()`` prepares a kernel the same way whoever started it (JupyterLab,
papermill, nbval):

- **Paths**: it makes the repository root (:data:`alte.paths.REPO_ROOT`) the
  working directory, so the notebooks' relative parameters (``DATA_DIR = "data"``,
  ``OUT_DIR = "reports/scratch/..."``) name the same folders as ``make report``,
  although JupyterLab starts kernels in ``notebooks/``.
- **Rendering**: static off-screen images (papermill, nbval, CI), or pyvista's
  interactive trame backend when a Jupyter server started the kernel for a page a
  person looks at (``JPY_SESSION_NAME`` set, as JupyterLab does). ``ALTE_RENDER=static``
  forces images; ``ALTE_RENDER=interactive`` (or ``setup("interactive")``) asks for
  live views, which still fall back to images in a kernel no page displays
  (papermill, nbconvert): a widget there would save a dead view, an image shows
  the figure in the saved notebook and its HTML. Live views need
  ``pyvista[jupyter]`` (trame, trame-pyvista, ipywidgets); without them ``setup``
  warns and renders images. Each live view is an ipywidget whose iframe is served
  by a trame server the kernel starts on 127.0.0.1: a browser on the same machine
  reaches it directly; for a remote JupyterLab set
  ``PYVISTA_TRAME_SERVER_PROXY_PREFIX=/proxy/`` (jupyter-server-proxy).

Importing this module in a kernel also silences what third-party imports would
send to the page and a person cannot act on (see :func:`quiet_kernel`), so a
notebook imports ``alte.lab.notebook`` before any other alte module.
``save_results`` writes the notebook's named results to JSON atomically (the
report runner collects them); ``save_figure`` (:func:`alte.lab.plot.render.save_figure`)
saves a figure with its caption.
"""

from __future__ import annotations

import importlib.util
import json
import os
import sys
import warnings
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from alte.errors import ParameterError
from alte.fsutil import atomic_path
from alte.lab.plot.render import interactive, save_figure, use_live_views
from alte.paths import REPO_ROOT

if TYPE_CHECKING:
    from alte.types import JSON

__all__ = [
    "INTERACTIVE_MODULES", "interactive", "live_frontend", "quiet_kernel", "save_figure",
    "save_results", "setup",
]

#: What pyvista's trame backend needs in the kernel (``pip install 'pyvista[jupyter]'``).
INTERACTIVE_MODULES = ("trame", "trame_pyvista", "trame_vtk", "ipywidgets", "nest_asyncio2")


def live_frontend() -> bool:
    """True when a Jupyter server started this kernel for a notebook page.

    jupyter_server sets ``JPY_SESSION_NAME`` (the notebook's path) in the kernels it
    starts; papermill, nbclient and nbval do not.
    """
    return bool(os.environ.get("JPY_SESSION_NAME"))


def _in_kernel() -> bool:
    if "ipykernel" not in sys.modules:
        return False
    from IPython import get_ipython

    return getattr(get_ipython(), "kernel", None) is not None


def quiet_kernel() -> None:
    """Keep third-party import side effects that a person cannot act on off the page.

    open3d, imported in a kernel, prints a WebVisualizer banner and starts WebRTC
    (alte draws with pyvista, never with it): ``OPEN3D_DISABLE_WEB_VISUALIZER``
    turns that off. dash, which open3d imports, opens a ``dash`` comm at import for
    a JupyterLab extension alte does not install: JupyterLab logs "Exception opening
    new comm", nbclient "No handler found for comm target 'dash'". Importing dash's
    Jupyter module here with that one comm not created leaves dash as it is where
    comms are unavailable (its documented fallback). Runs when this module is
    imported, so before anything imports open3d; does nothing outside a kernel.
    """
    if not _in_kernel():
        return
    os.environ.setdefault("OPEN3D_DISABLE_WEB_VISUALIZER", "true")
    if "dash._jupyter" in sys.modules or importlib.util.find_spec("dash") is None:
        return
    import comm
    from comm.base_comm import BaseComm

    create = comm.create_comm

    def no_dash_comm(*args: object, **kwargs: object) -> BaseComm:
        if kwargs.get("target_name") == "dash":
            return None  # type: ignore[return-value]  # dash's fallback without comms
        return create(*args, **kwargs)

    comm.create_comm = no_dash_comm
    try:
        importlib.import_module("dash._jupyter")
    finally:
        comm.create_comm = create


def _render_mode(mode: str | None) -> str:
    chosen = mode or os.environ.get("ALTE_RENDER") or (
        "interactive" if live_frontend() else "static")
    if chosen not in {"static", "interactive"}:
        raise ParameterError(f"render mode {chosen!r}: expected 'static' or 'interactive'")
    if chosen == "static" or not live_frontend():
        return "static"  # no page shows a widget: the saved notebook needs an image
    missing = [m for m in INTERACTIVE_MODULES if importlib.util.find_spec(m) is None]
    if missing:
        warnings.warn(f"interactive 3D views need {', '.join(missing)} (pip install "
                      "'pyvista[jupyter]'); rendering static images instead", stacklevel=3)
        return "static"
    return "interactive"


def setup(mode: str | None = None) -> str:
    """Work from the repository root and select the back-ends; ``"static"`` or ``"interactive"``.

    ``mode`` overrides the ``ALTE_RENDER`` environment variable; without either, a
    kernel JupyterLab started is interactive, any other static. Interactive needs a
    live page (:func:`live_frontend`) and trame; without them, static.
    """
    import matplotlib
    import pyvista as pv

    quiet_kernel()
    chosen = _render_mode(mode)
    if (REPO_ROOT / "pyproject.toml").is_file():  # a checkout, not an installed wheel
        os.chdir(REPO_ROOT)
    use_live_views(chosen == "interactive")
    if not os.environ.get("DISPLAY"):  # skip VTK's failing X attempt: render with EGL
        os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
    if chosen == "static":
        matplotlib.use("Agg")
        pv.OFF_SCREEN = True
        pv.set_jupyter_backend("static")
    else:
        pv.set_jupyter_backend("trame")
    _show_figures_as_png()
    return chosen


def _show_figures_as_png() -> None:
    """In an IPython kernel, display matplotlib ``Figure`` objects as PNG images (the
    Agg back-end registers no display formatter, so a figure would show as text)."""
    try:
        from IPython import get_ipython
        from IPython.core.pylabtools import select_figure_formats
    except ImportError:  # pragma: no cover - IPython is a dependency of the notebooks
        return
    shell = get_ipython()
    if shell is not None:
        select_figure_formats(shell, {"png"}, bbox_inches="tight")


def _jsonable(value: object) -> JSON:
    if isinstance(value, Mapping):
        return {str(k): _jsonable(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_jsonable(v) for v in value]
    if isinstance(value, np.ndarray):
        return _jsonable(value.tolist())
    if isinstance(value, np.generic):
        return _jsonable(value.item())
    if isinstance(value, Path):
        return str(value)
    if value is None or isinstance(value, str | int | float | bool):
        return value
    raise ParameterError(f"save_results: {type(value).__name__} values cannot be written "
                         "as JSON; pass numbers, text, lists, dicts, arrays or paths")


def save_results(out_dir: str | os.PathLike[str], results: Mapping[str, object]) -> Path:
    """Write ``results`` to ``out_dir/results.json`` (sorted keys, atomic, overwrites)."""
    path = Path(out_dir) / "results.json"
    with atomic_path(path, overwrite=True) as tmp:
        tmp.write_text(json.dumps(_jsonable(results), indent=2, sort_keys=True) + "\n")
    return path


quiet_kernel()
