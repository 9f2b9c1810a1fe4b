"""Plot helpers for the notebooks: matplotlib for 2D, pyvista (off-screen) for 3D.

Every function that builds a whole figure returns it with its caption (:mod:`alte.lab.plot.figure`);
:func:`save_figure` saves both, :func:`show` shows (and saves) a 3D view.
"""

from alte.lab.plot.figure import Caption, Plot, View
from alte.lab.plot.render import new_plotter, save_figure, show, view

__all__ = ["Caption", "Plot", "View", "new_plotter", "save_figure", "show", "view"]
