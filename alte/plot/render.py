"""One place that creates pyvista plotters and shows them the right way.

Headless (papermill, nbval, CI) a plotter renders off-screen to a PNG that is
also displayed inline; in JupyterLab with a browser attached it is interactive
(trame). Notebooks never choose: they call :func:`new_plotter` and :func:`show`.
"""

from __future__ import annotations

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


def show(plotter: Any, out_dir: str | os.PathLike[str] | None = None,
         name: str | None = None) -> Path | None:
    """Display ``plotter``; with ``out_dir`` and ``name`` also save ``figures/name.png``."""
    path = None
    if out_dir is not None and name is not None:
        path = Path(out_dir) / "figures" / f"{name}.png"
        with atomic_path(path, overwrite=True) as tmp:
            plotter.screenshot(str(tmp) + ".png")
            Path(str(tmp) + ".png").replace(tmp)
    if interactive():
        plotter.show()
    else:
        from IPython.display import Image, display

        if path is None:
            img = plotter.screenshot(None, return_img=True)
            from PIL import Image as PILImage

            pil = PILImage.fromarray(img)
            display(pil)
        else:
            display(Image(filename=str(path)))
        plotter.close()
    return path
