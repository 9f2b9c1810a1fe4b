"""One place that creates pyvista plotters, shows them the right way and saves every figure.

Headless (papermill, nbval, CI) a plotter renders off-screen to a PNG that is
displayed inline; in JupyterLab (:func:`interactive`, chosen by
:func:`alte.lab.notebook.setup`) it is a live trame view, displayed with the same PNG
beside it so that the HTML of a notebook saved without widget state (JupyterLab's
default) still shows the figure. Notebooks never choose: they save a figure with
:func:`save_figure` (a :class:`~alte.lab.plot.figure.Plot` or a :class:`~alte.lab.plot.figure.View`,
each with its caption; :func:`show` for a view, which returns nothing) and the view is
shown as it should be.
"""

from __future__ import annotations

import base64
import io
import os
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import TYPE_CHECKING, Protocol, runtime_checkable

from alte.errors import ParameterError
from alte.fsutil import atomic_path
from alte.lab.plot.figure import Caption, Plot, View, figure_path, write_caption

if TYPE_CHECKING:
    import pyvista as pv

__all__ = ["Draw", "interactive", "new_plotter", "save_figure", "save_figures", "show",
           "use_live_views", "view"]

#: A function that draws one captioned figure (or raises ParameterError: nothing to draw).
Draw = Callable[[], Plot]

_STATE = {"interactive": False}


def interactive() -> bool:
    """True when 3D views should be live widgets (a page displays this kernel)."""
    return _STATE["interactive"]


def use_live_views(live: bool) -> None:
    """Show 3D views as live widgets (True) or as images (False)."""
    _STATE["interactive"] = live


def new_plotter(shape: tuple[int, int] = (1, 1),
                window_size: tuple[int, int] = (900, 600)) -> pv.Plotter:
    """A pyvista plotter, off-screen unless the session is interactive."""
    import pyvista as pv

    return pv.Plotter(shape=shape, window_size=list(window_size), off_screen=not interactive())


def view(caption: Caption, shape: tuple[int, int] = (1, 1),
         window_size: tuple[int, int] = (900, 600)) -> View:
    """A new plotter (:func:`new_plotter`) with the caption of the figure it will show."""
    return View(new_plotter(shape, window_size), caption)


@runtime_checkable
class _Widget(Protocol):
    """What pyvista's live view (a trame widget) is displayed with."""

    def _repr_mimebundle_(self) -> dict[str, object]: ...


def _png(plotter: pv.Plotter) -> bytes:
    buffer = io.BytesIO()
    plotter.screenshot(buffer, return_img=False)  # pyvista writes a PNG into a BytesIO
    return buffer.getvalue()


def _display(plotter: pv.Plotter, png: bytes) -> None:
    """Display a rendered plotter: its PNG (then closed), or a live view beside it."""
    from IPython.display import Image, display

    widget = plotter.show(return_viewer=True) if interactive() else None  # not yet shown
    if not isinstance(widget, _Widget):
        display(Image(data=png, format="png"))
        plotter.close()
        return
    bundle = dict(widget._repr_mimebundle_())
    bundle["image/png"] = base64.b64encode(png).decode("ascii")
    display(bundle, raw=True)


def show(item: View, out_dir: str | os.PathLike[str] | None = None,
         name: str | None = None) -> None:
    """Display a 3D view; with ``out_dir`` and ``name`` also save it with its caption
    (:func:`save_figure`). A static plotter is closed once shown.

    Returns nothing, so a cell ending in ``show(...)`` prints no value."""
    if out_dir is not None and name is not None:
        save_figure(item, out_dir, name)
    else:
        _display(item.plotter, _png(item.plotter))


def save_figure(item: Plot | View, out_dir: str | os.PathLike[str], name: str) -> Path:
    """Save ``item`` as ``out_dir/figures/name.png`` with its caption beside it
    (``name.json``, see :func:`alte.lab.plot.figure.write_caption`); atomic, overwrites.

    A :class:`View` is also displayed (a static plotter is closed once rendered, so
    saving is its last use); a :class:`Plot` is displayed by the notebook cell that
    ends with it. A figure without a caption is refused: the report shows every figure
    with one.
    """
    if not isinstance(item, Plot | View):
        raise ParameterError(
            f"save_figure(..., {name!r}): got a {type(item).__name__} without a caption; "
            "save the Plot or View an alte.lab.plot function returns, or wrap the figure: "
            "Plot(figure, Caption(title, text))")
    path = figure_path(out_dir, name)
    png = item.png() if isinstance(item, Plot) else _png(item.plotter)
    with atomic_path(path, overwrite=True) as tmp:
        tmp.write_bytes(png)
    write_caption(path, item.caption)
    if isinstance(item, View):
        _display(item.plotter, png)
    return path


def save_figures(figures: Iterable[tuple[str, Draw]], out_dir: str | os.PathLike[str],
                 close: bool = True, *, jobs: int = 1) -> dict[str, Path | str]:
    """Draw each (name, draw) and save it with :func:`save_figure`; a figure that cannot be
    drawn (:class:`ParameterError`) is recorded as ``"not drawn: <reason>"``. ``close=False``
    leaves the figures open. ``jobs > 1`` draws them in that many fresh processes
    (matplotlib draws on one core; a chapter's dozen figures over a grid of thousands of
    runs take tens of seconds), the same files; no figure is then left open."""
    if jobs > 1:
        return _save_in_processes(list(figures), out_dir, jobs)
    import matplotlib.pyplot as plt

    out: dict[str, Path | str] = {}
    for name, draw in figures:
        try:
            plot = draw()
        except ParameterError as err:
            out[name] = f"not drawn: {err}"
            continue
        out[name] = save_figure(plot, out_dir, name)
        if close:
            plt.close(plot.figure)
    return out


def _draw_png(name: str, draw: Draw, out_dir: str | os.PathLike[str]
              ) -> tuple[Path, Caption] | str:
    """One figure of :func:`save_figures` drawn and its PNG written (in a worker
    process): its path and caption, or why it was not drawn. The caption is written by
    the caller, in the figures' order (the order the report shows them in)."""
    import matplotlib.pyplot as plt

    try:
        plot = draw()
    except ParameterError as err:
        return f"not drawn: {err}"
    path = figure_path(out_dir, name)
    png = plot.png()
    plt.close(plot.figure)
    with atomic_path(path, overwrite=True) as tmp:
        tmp.write_bytes(png)
    return path, plot.caption


def _save_in_processes(figures: list[tuple[str, Draw]], out_dir: str | os.PathLike[str],
                       jobs: int) -> dict[str, Path | str]:
    """:func:`save_figures` with ``jobs`` spawned processes (``draw`` must pickle)."""
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    context = multiprocessing.get_context("spawn")  # a kernel's threads never fork
    with ProcessPoolExecutor(min(jobs, max(len(figures), 1)), mp_context=context) as pool:
        drawn = [pool.submit(_draw_png, name, draw, out_dir) for name, draw in figures]
        out: dict[str, Path | str] = {}
        for (name, _), future in zip(figures, drawn, strict=True):
            result = future.result()
            if isinstance(result, str):
                out[name] = result
            else:
                write_caption(*result)
                out[name] = result[0]
        return out
