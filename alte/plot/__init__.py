"""Plot helpers for the notebooks: matplotlib for 2D, pyvista (off-screen) for 3D."""

from alte.plot.render import new_plotter, show

__all__ = ["new_plotter", "show"]
