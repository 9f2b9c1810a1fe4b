"""One place that creates pyvista plotters and shows them the right way.

Headless (papermill, nbval, CI) a plotter renders off-screen to a PNG that is
displayed inline; in JupyterLab (:func:`alte.notebook.interactive`) it is a live
trame view, displayed with the same PNG beside it so that the HTML of a notebook
saved without widget state (JupyterLab's default) still shows the figure.
Notebooks never choose: they call :func:`new_plotter` and :func:`show`.
"""

from __future__ import annotations

import base64
import io
import os
from pathlib import Path
from typing import Any

from alte.fsutil import atomic_path
from alte.notebook import interactive

__all__ = ["new_plotter", "show"]


def new_plotter(shape: tuple[int, int] = (1, 1), window_size: tuple[int, int] = (900, 600),
                **kwargs: Any) -> Any:
    """A pyvista plotter, off-screen unless the session is interactive."""
    import pyvista as pv

    return pv.Plotter(shape=shape, window_size=list(window_size), off_screen=not interactive(),
                      **kwargs)


def _png(plotter: Any) -> bytes:
    buffer = io.BytesIO()
    plotter.screenshot(buffer, return_img=False)  # pyvista writes a PNG into a BytesIO
    return buffer.getvalue()


def show(plotter: Any, out_dir: str | os.PathLike[str] | None = None,
         name: str | None = None) -> None:
    """Display ``plotter``; with ``out_dir`` and ``name`` also save ``out_dir/figures/name.png``.

    Returns nothing, so a cell ending in ``show(...)`` prints no value. A static
    plotter is closed once shown; a live one stays open for its view.
    """
    from IPython.display import Image, display

    png = _png(plotter)
    if out_dir is not None and name is not None:
        with atomic_path(Path(out_dir) / "figures" / f"{name}.png", overwrite=True) as tmp:
            tmp.write_bytes(png)
    if not interactive():
        display(Image(data=png, format="png"))
        plotter.close()
        return
    view = plotter.show(return_viewer=True)  # the trame widget, not yet displayed
    bundle = dict(view._repr_mimebundle_())
    bundle["image/png"] = base64.b64encode(png).decode("ascii")
    display(bundle, raw=True)
