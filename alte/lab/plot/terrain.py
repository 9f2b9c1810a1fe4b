"""Figures of chapters 4-5: the terrain, the registered cloud and map views from above.

Figures take arrays (or a mapper / true surface) and return a
:class:`~alte.lab.plot.figure.Plot` (a ``matplotlib.figure.Figure`` with its caption), 3D views
a :class:`~alte.lab.plot.figure.View`; the notebooks display and save them with
:func:`alte.lab.plot.render.save_figure`. Maps are drawn from above: every known cell as a
rectangle coloured by height (2D maps) or by its top (occupied 3D cells, drawn low to
high so the highest cell of a column shows), which is how figures 5.2-5.5 read.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
from matplotlib.collections import PolyCollection
from matplotlib.figure import Figure

from alte.lab.plot.arrays import Floats
from alte.lab.plot.figure import Caption, Plot, View
from alte.lab.plot.render import view
from alte.mappers.base import Mapper

if TYPE_CHECKING:
    import pyvista as pv
    from matplotlib.axes import Axes

    from alte.metrics.surface import TrueSurface

__all__ = ["MAPS", "SWEEPS", "add_terrain", "cloud_figure", "map_grid_figure", "terrain_view"]

TERRAIN = Caption("Terrain (figs. 4.1, 4.7, 4.13, ...)",
                  "The simulated terrain {TERRAIN} and its control volume.")
CLOUD = Caption("Registered cloud", "The registered point cloud of {TERRAIN}.")
#: A terrain's maps with the thesis' chapter 4 parameters (the default of
#: :func:`map_grid_figure`).
MAPS = Caption("Maps with the chapter 4 parameters",
               "The two mappers of this case with the thesis' chapter 4 parameters.")
#: The thesis' sweep figures 5.2-5.5, per mapper.
SWEEPS = {
    "quadtree": Caption("Quadtree sweep (fig. 5.2)", "Quadtree maps over max_points."),
    "octomap": Caption("Octomap sweep (fig. 5.3)", "Octomap maps over resolution."),
    "alte2d": Caption("2D-ALTE sweep (fig. 5.4)", "2D-ALTE maps for the thesis' settings."),
    "alte3d": Caption("3D-ALTE sweep (fig. 5.5)", "3D-ALTE maps for the thesis' settings."),
}

_MAX_DOTS = 60_000


def cloud_figure(points: Floats, title: str = "registered cloud") -> Plot:
    """Top view of a cloud coloured by height (thinned to at most 60 000 dots)."""
    step = max(1, len(points) // _MAX_DOTS)
    pts = points[::step]
    fig = Figure(figsize=(6, 5))
    ax = fig.add_subplot()
    dots = ax.scatter(pts[:, 0], pts[:, 1], c=pts[:, 2], s=0.5, cmap="viridis")
    fig.colorbar(dots, ax=ax, label="z [m]")
    ax.set_aspect("equal")
    ax.set_title(title)
    return Plot(fig, CLOUD)


def _draw_cells(ax: Axes, mapper: Mapper) -> PolyCollection:
    cells = mapper.cells()
    keep = np.isfinite(cells.centers).all(axis=1)
    if mapper.dims == 3:
        keep &= cells.occupied.astype(bool)
    c, h = cells.centers[keep], cells.sizes[keep] / 2.0
    top = c[:, 2] + h[:, 2]
    order = np.argsort(top)
    c, h, top = c[order], h[order], top[order]
    signs = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]])
    quads = c[:, None, :2] + signs[None] * h[:, None, :2]
    # matplotlib's stub asks for a sequence of (4, 2) arrays; it takes one (K, 4, 2) array
    coll = PolyCollection(quads, array=top, cmap="viridis",  # type: ignore[arg-type]
                          edgecolors="k", linewidths=0.1)
    ax.add_collection(coll)
    if len(c):
        ax.set_xlim(quads[..., 0].min(), quads[..., 0].max())
        ax.set_ylim(quads[..., 1].min(), quads[..., 1].max())
    ax.set_aspect("equal")
    return coll


def map_grid_figure(mappers: Sequence[Mapper], titles: Sequence[str], columns: int = 3, *,
                    caption: Caption = MAPS) -> Plot:
    """Maps side by side from above, one panel per mapper (figures 4.x and 5.2-5.5:
    ``caption`` :data:`MAPS` or one of :data:`SWEEPS`)."""
    rows = max(1, -(-len(mappers) // columns))
    cols = min(columns, max(1, len(mappers)))
    fig = Figure(figsize=(4.2 * cols, 3.8 * rows))
    axes = np.atleast_1d(fig.subplots(rows, cols)).reshape(-1)
    for ax, mapper, title in zip(axes, mappers, titles, strict=False):
        coll = _draw_cells(ax, mapper)
        fig.colorbar(coll, ax=ax, label="height [m]", shrink=0.8)
        ax.set_title(title, fontsize=9)
    for ax in axes[len(mappers):]:
        ax.set_visible(False)
    return Plot(fig, caption)


def add_terrain(plotter: pv.Plotter, surface: TrueSurface, bounds: Floats | None = None,
                opacity: float = 1.0) -> pv.Plotter:
    """Add a ground-truth mesh (a :class:`~alte.metrics.TrueSurface`) coloured by object,
    clipped to ``bounds`` (2, 3) when given (the control volume)."""
    import pyvista as pv

    faces = np.hstack([np.full((len(surface.triangles), 1), 3), surface.triangles]).reshape(-1)
    mesh = pv.PolyData(surface.vertices, faces)
    mesh.cell_data["object"] = surface.object_ids
    if bounds is not None:
        mesh = mesh.clip_box(np.asarray(bounds, dtype=np.float64).T.reshape(-1).tolist(),
                             invert=False)
    plotter.add_mesh(mesh, scalars="object", cmap="tab20", opacity=opacity, show_scalar_bar=False)
    return plotter


def terrain_view(surface: TrueSurface, bounds: Floats | None = None) -> View:
    """The ground-truth mesh coloured by object, clipped to the control volume ``bounds``
    (figures 4.1, 4.7, 4.13, ...)."""
    terrain = view(TERRAIN)
    add_terrain(terrain.plotter, surface, bounds)
    return terrain
