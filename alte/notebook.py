"""Helpers the chapter notebooks call, so that the notebooks hold no logic.

``setup()`` chooses the rendering mode once: static off-screen images when no
browser or display is attached (papermill, nbval, CI), pyvista's interactive trame
backend in a JupyterLab session (``JPY_SESSION_NAME`` set) or with
``ALTE_RENDER=interactive``. Interactive mode needs ``pyvista[jupyter]`` (trame,
trame-pyvista, ipywidgets); without them ``setup`` warns and renders statically. In
interactive mode :func:`alte.plot.render.show` displays an ipywidget whose iframe
is served by a trame server the kernel starts on 127.0.0.1: a browser on the same
machine reaches it directly; for a remote JupyterLab set
``PYVISTA_TRAME_SERVER_PROXY_PREFIX=/proxy/`` so the iframe goes through
jupyter-server-proxy. ``save_results`` writes the notebook's named results to JSON
atomically (the report runner collects them).
"""

from __future__ import annotations

import importlib.util
import json
import os
import warnings
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from alte.errors import ParameterError
from alte.fsutil import atomic_path

__all__ = ["INTERACTIVE_MODULES", "interactive", "save_figure", "save_results", "setup"]

_STATE = {"interactive": False}
#: What pyvista's trame backend needs in the kernel (``pip install 'pyvista[jupyter]'``).
INTERACTIVE_MODULES = ("trame", "trame_pyvista", "trame_vtk", "ipywidgets", "nest_asyncio2")


def interactive() -> bool:
    """True when 3D views should be interactive (a browser is attached)."""
    return _STATE["interactive"]


def setup(mode: str | None = None) -> str:
    """Select matplotlib/pyvista back-ends; returns ``"static"`` or ``"interactive"``.

    ``mode`` overrides the ``ALTE_RENDER`` environment variable; without either,
    a kernel started by papermill/nbval (no ``JPY_SESSION_NAME``) renders statically.
    Interactive falls back to static, with a warning, when trame is not installed.
    """
    import matplotlib
    import pyvista as pv

    chosen = mode or os.environ.get("ALTE_RENDER") or (
        "interactive" if os.environ.get("JPY_SESSION_NAME") else "static"
    )
    if chosen not in {"static", "interactive"}:
        raise ParameterError(f"render mode {chosen!r}: expected 'static' or 'interactive'")
    missing = [m for m in INTERACTIVE_MODULES if importlib.util.find_spec(m) is None]
    if chosen == "interactive" and missing:
        warnings.warn(f"interactive 3D views need {', '.join(missing)} (pip install "
                      "'pyvista[jupyter]'); rendering static images instead", stacklevel=2)
        chosen = "static"
    _STATE["interactive"] = chosen == "interactive"
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


def _jsonable(value: Any) -> Any:
    if isinstance(value, Mapping):
        return {str(k): _jsonable(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_jsonable(v) for v in value]
    if isinstance(value, np.ndarray):
        return _jsonable(value.tolist())
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, Path):
        return str(value)
    return value


def save_results(out_dir: str | os.PathLike[str], results: Mapping[str, Any]) -> Path:
    """Write ``results`` to ``out_dir/results.json`` (sorted keys, atomic, overwrites)."""
    path = Path(out_dir) / "results.json"
    with atomic_path(path, overwrite=True) as tmp:
        tmp.write_text(json.dumps(_jsonable(results), indent=2, sort_keys=True) + "\n")
    return path


def save_figure(fig: Any, out_dir: str | os.PathLike[str], name: str) -> Path:
    """Save a matplotlib figure as ``out_dir/figures/name.png`` (atomic, overwrites)."""
    path = Path(out_dir) / "figures" / f"{name}.png"
    with atomic_path(path, overwrite=True) as tmp:
        fig.savefig(tmp, format="png", dpi=110, bbox_inches="tight",
                    metadata={"Software": None})
    return path
