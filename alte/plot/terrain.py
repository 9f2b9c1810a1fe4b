"""Figures of chapters 4-5: the terrain, the registered cloud and map views from above.

Figures take arrays (or a mapper / true surface) and
return a ``matplotlib.figure.Figure``; the notebooks display and save them with
:func:`alte.notebook.save_figure`. Maps are drawn from above: every known cell as a
rectangle coloured by height (2D maps) or by its top (occupied 3D cells, drawn low to
high so the highest cell of a column shows), which is how figures 5.2-5.5 read.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from matplotlib.collections import PolyCollection
from matplotlib.figure import Figure

__all__ = ["add_terrain", "cloud_figure", "map_grid_figure"]

_MAX_DOTS = 60_000


def cloud_figure(points: np.ndarray, title: str = "registered cloud") -> Figure:
    """Top view of a cloud coloured by height (thinned to at most 60 000 dots)."""
    step = max(1, len(points) // _MAX_DOTS)
    pts = points[::step]
    fig = Figure(figsize=(6, 5))
    ax = fig.add_subplot()
    dots = ax.scatter(pts[:, 0], pts[:, 1], c=pts[:, 2], s=0.5, cmap="viridis")
    fig.colorbar(dots, ax=ax, label="z [m]")
    ax.set_aspect("equal")
    ax.set_title(title)
    return fig


def _draw_cells(ax: Any, mapper: Any) -> Any:
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
    coll = PolyCollection(quads, array=top, cmap="viridis", edgecolors="k", linewidths=0.1)
    ax.add_collection(coll)
    if len(c):
        ax.set_xlim(quads[..., 0].min(), quads[..., 0].max())
        ax.set_ylim(quads[..., 1].min(), quads[..., 1].max())
    ax.set_aspect("equal")
    return coll


def map_grid_figure(mappers: Sequence[Any], titles: Sequence[str], columns: int = 3) -> Figure:
    """Maps side by side from above, one panel per mapper (figures 4.x and 5.2-5.5)."""
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
    return fig


def add_terrain(plotter: Any, surface: Any, bounds: np.ndarray | None = None,
                opacity: float = 1.0) -> Any:
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
