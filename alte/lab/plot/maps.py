"""Map figures: 2D segments and occupancy (fig. 4.17), 3D cell boxes (fig. 3.15), counts.

Every cell set is drawn as one collection (matplotlib ``PolyCollection`` or one
pyvista ``UnstructuredGrid``), never one artist per cell, so maps with tens of
thousands of cells draw quickly. Unknown cells (NaN value, the 2D mappers'
cells without points) are drawn grey, never like ground.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Protocol

import numpy as np
from numpy.typing import ArrayLike

from alte.lab.plot.arrays import Floats, polygons
from alte.lab.plot.figure import Caption, Plot, View
from alte.lab.plot.render import view
from alte.lab.studies.analysis.tradeoff import mapper_title
from alte.mappers.base import Cells
from alte.mappers.quad.quadmap import plane_height

if TYPE_CHECKING:
    import pyvista as pv
    from matplotlib.axes import Axes
    from matplotlib.collections import PolyCollection
    from matplotlib.lines import Line2D
    from pyvista.plotting._typing import ColormapOptions, ScalarBarArgs

    from alte.pipeline.maprun import MapRun

__all__ = [
    "ALTE2D_TIMELAPSE",
    "ALTE3D_TIMELAPSE",
    "OCTOMAP_TIMELAPSE",
    "QUADTREE_TIMELAPSE",
    "UNKNOWN_COLOR",
    "add_cells_3d",
    "add_timelapse_3d",
    "basis_functions_figure",
    "cells_mesh",
    "plot_basis_functions_over_time",
    "plot_map_2d",
    "plot_timelapse_2d",
    "timelapse_view",
]

#: Captions of the thesis' time-lapse figures, one per mapper (chapter 3).
QUADTREE_TIMELAPSE = Caption("Quadtree over time (fig. 3.3)",
                             "Quadtree rebuilt as the scans arrive.")
OCTOMAP_TIMELAPSE = Caption("Octomap over time (fig. 3.7)",
                            "Octomap's occupied voxels as scans arrive.")
ALTE2D_TIMELAPSE = Caption(
    "2D-ALTE over time (fig. 3.14)",
    "2D-ALTE's cells as scans arrive; right: the binary grid proposed in chapter 6.")
ALTE3D_TIMELAPSE = Caption("3D-ALTE over time (fig. 3.17)",
                           "3D-ALTE's occupied cells as scans arrive.")
BASIS_FUNCTIONS = Caption("Basis functions against mission time",
                          "Map size as the mission proceeds: 2D mappers left, 3D mappers right.")


class Snapshot(Protocol):
    """A map at one mission time (:class:`alte.pipeline.maprun.Snapshot`)."""

    @property
    def time(self) -> float: ...

    @property
    def cells(self) -> Cells: ...

UNKNOWN_COLOR = (0.8, 0.8, 0.8, 1.0)
_SIGNS_2D = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]], dtype=np.float64)
# VTK hexahedron order: bottom face counter-clockwise, then the top face.
_SIGNS_3D = np.array([[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1],
                      [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]], dtype=np.float64)


def _rectangles(cells: Cells) -> Floats:
    """(K, 4, 2) footprints of the cells."""
    half = cells.sizes[:, None, :2] / 2
    return cells.centers[:, None, :2] + _SIGNS_2D[None] * half


def _frame_axes(ax: Axes, verts: Floats, title: str | None) -> None:
    if len(verts):
        lo, hi = verts.reshape(-1, 2).min(axis=0), verts.reshape(-1, 2).max(axis=0)
        ax.set_xlim(lo[0], hi[0])
        ax.set_ylim(lo[1], hi[1])
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    if title:
        ax.set_title(title)


def _occupancy_panel(cells: Cells, ax: Axes, verts: Floats, height_threshold: float | None,
                     ground: float | Floats) -> PolyCollection:
    """Black occupied, white free, grey unknown cells (occupancy from heights if asked)."""
    import matplotlib as mpl
    from matplotlib.collections import PolyCollection

    known = np.isfinite(cells.centers[:, 2])
    occupied = cells.occupied
    if height_threshold is not None:
        above = cells.centers[:, 2] - plane_height(ground, cells.centers[:, :2])
        occupied = known & (np.nan_to_num(above, nan=-np.inf) > height_threshold)
    colours = np.where(occupied[:, None], (0.0, 0.0, 0.0, 1.0), (1.0, 1.0, 1.0, 1.0))
    colours[~known & ~occupied] = UNKNOWN_COLOR
    occ = PolyCollection(polygons(verts), facecolors=colours, edgecolors=(0.5, 0.5, 0.5, 1.0),
                         linewidths=0.2)
    ax.add_collection(occ)
    handles = [mpl.patches.Patch(facecolor=c, edgecolor="k", label=lab) for c, lab in
               (((0, 0, 0, 1), "occupied"), ((1, 1, 1, 1), "free"), (UNKNOWN_COLOR, "unknown"))]
    ax.legend(handles=handles, loc="upper right", fontsize="small")
    return occ


def plot_map_2d(cells: Cells, ax_segments: Axes, ax_occupancy: Axes | None = None, *,
                title: str | None = None, cmap: str = "viridis",
                height_threshold: float | None = None,
                ground: float | Floats = 0.0) -> tuple[PolyCollection, PolyCollection | None]:
    """Segments coloured by height (left) and the occupancy grid (right), as fig. 4.17.

    Heights come from ``centers[:, 2]``; unknown cells are grey in both panels,
    occupied cells black and free cells white in the occupancy panel. The grid is
    ``cells.occupied`` unless ``height_threshold`` is given: then a cell is occupied
    when its height rises that much over ``ground`` (z or plane a,b,c,d), the binary
    grid of thesis ch. 6 for 2D-ALTE's height map. Returns the two
    ``PolyCollection`` objects (the second None without ``ax_occupancy``).
    """
    import matplotlib as mpl
    from matplotlib.collections import PolyCollection

    verts = _rectangles(cells)
    z = cells.centers[:, 2]
    known = np.isfinite(z)
    norm = mpl.colors.Normalize(*(np.nanmin(z), np.nanmax(z)) if known.any() else (0, 1))
    colours = np.tile(UNKNOWN_COLOR, (len(cells), 1))
    colours[known] = mpl.colormaps[cmap](norm(z[known]))
    seg = PolyCollection(polygons(verts), facecolors=colours, edgecolors="k", linewidths=0.2)
    ax_segments.add_collection(seg)
    mappable = mpl.cm.ScalarMappable(norm=norm, cmap=cmap)
    ax_segments.figure.colorbar(mappable, ax=ax_segments, label="height [m]", shrink=0.8)
    _frame_axes(ax_segments, verts, f"{title} - segments" if title else "segments")
    if ax_occupancy is None:
        return seg, None
    occ = _occupancy_panel(cells, ax_occupancy, verts, height_threshold, ground)
    _frame_axes(ax_occupancy, verts, f"{title} - occupancy" if title else "occupancy")
    return seg, occ


def cells_mesh(cells: Cells, occupied_only: bool = True,
               color_by: str = "height") -> pv.UnstructuredGrid:
    """One pyvista ``UnstructuredGrid``: boxes for 3D cells, flat squares for 2D cells.

    ``color_by``: ``height`` (top of the cell, fig. 3.15), ``value`` or ``level``;
    the scalars are stored under that name. Unknown (NaN-height) cells are skipped.
    """
    import pyvista as pv

    if color_by not in {"height", "value", "level"}:
        raise ValueError(f"color_by={color_by!r}: expected height, value or level")
    mask = np.isfinite(cells.centers).all(axis=1)
    if occupied_only:
        mask &= cells.occupied
    centers, sizes = cells.centers[mask], cells.sizes[mask]
    flat = sizes[:, 2] <= 0
    blocks, points, offset = {}, [], 0
    for cell_type, signs, sel in ((pv.CellType.HEXAHEDRON, _SIGNS_3D, ~flat),
                                  (pv.CellType.QUAD, np.c_[_SIGNS_2D, np.zeros(4)], flat)):
        k = int(sel.sum())
        if k:
            corners = centers[sel, None] + signs[None] * sizes[sel, None] / 2
            points.append(corners.reshape(-1, 3))
            blocks[cell_type] = offset + np.arange(k * len(signs)).reshape(k, len(signs))
            offset += k * len(signs)
    if not blocks:
        return pv.UnstructuredGrid()
    order = np.r_[np.flatnonzero(~flat), np.flatnonzero(flat)]
    grid = pv.UnstructuredGrid(blocks, np.concatenate(points))
    scalars = {"height": (centers + sizes / 2)[:, 2], "value": cells.value[mask],
               "level": cells.level[mask].astype(np.float64)}[color_by]
    grid.cell_data[color_by] = scalars[order]
    return grid


def add_cells_3d(plotter: pv.Plotter, cells: Cells, occupied_only: bool = True,
                 color_by: str = "height", cmap: ColormapOptions = "viridis", *,
                 show_edges: bool = True,
                 scalar_bar_args: ScalarBarArgs | None = None) -> pv.UnstructuredGrid:
    """Add the cells to a pyvista ``plotter`` coloured by ``color_by``; returns the mesh."""
    grid = cells_mesh(cells, occupied_only, color_by)
    if grid.n_cells == 0:
        return grid
    plotter.add_mesh(grid, scalars=color_by, cmap=cmap, show_edges=show_edges,
                     edge_color="black", line_width=0.5,
                     scalar_bar_args=scalar_bar_args)
    return grid


def plot_basis_functions_over_time(times: ArrayLike, counts: ArrayLike, ax: Axes,
                                   label: str | None = None) -> Line2D:
    """Step plot of the number of basis functions against mission time; returns the line."""
    (line,) = ax.step(np.asarray(times, dtype=np.float64), np.asarray(counts), where="post",
                      label=label)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("basis functions")
    if label:
        ax.legend()
    return line


def basis_functions_figure(runs: Mapping[str, MapRun]) -> Plot:
    """Basis functions against mission time per run (mapper name -> a run made with
    snapshots): 2D mappers left, 3D mappers right."""
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(11, 4))
    for name, run in runs.items():
        plot_basis_functions_over_time(run.log.times, run.log.basis_functions,
                                       axes[0 if run.mapper.dims == 2 else 1],
                                       mapper_title(name))
    return Plot(fig, BASIS_FUNCTIONS)


def plot_timelapse_2d(snapshots: Sequence[Snapshot], title: str = "", *, caption: Caption,
                      height_threshold: float | None = None) -> Plot:
    """One row per snapshot: segments left, occupancy right (occupancy from heights with
    ``height_threshold``, see :func:`plot_map_2d`).

    The thesis' time-lapse figures 3.3 and 3.14 (``caption``: :data:`QUADTREE_TIMELAPSE`,
    :data:`ALTE2D_TIMELAPSE`).
    """
    import matplotlib.pyplot as plt

    rows = max(len(snapshots), 1)
    fig, axes = plt.subplots(rows, 2, figsize=(11, 4.2 * rows), squeeze=False)
    for (ax_seg, ax_occ), snap in zip(axes, snapshots, strict=False):
        plot_map_2d(snap.cells, ax_seg, ax_occ, title=f"{title} t = {snap.time:.1f} s",
                    height_threshold=height_threshold)
    fig.tight_layout()
    return Plot(fig, caption)


def add_timelapse_3d(plotter: pv.Plotter, snapshots: Sequence[Snapshot],
                     title: str = "") -> None:
    """Fill a ``(1, len(snapshots))`` plotter with the occupied cells of each snapshot,
    coloured by height."""
    for col, snap in enumerate(snapshots):
        plotter.subplot(0, col)
        add_cells_3d(plotter, snap.cells)
        plotter.add_text(f"{title} t = {snap.time:.1f} s", font_size=9)
        plotter.renderer.show_axes()  # what Plotter.show_axes calls (typed)
    plotter.link_views()


def timelapse_view(snapshots: Sequence[Snapshot], title: str = "", *,
                   caption: Caption) -> View:
    """The thesis' time-lapse figures 3.7 and 3.17: one linked panel per snapshot
    (``caption``: :data:`OCTOMAP_TIMELAPSE`, :data:`ALTE3D_TIMELAPSE`)."""
    panels = max(len(snapshots), 1)
    lapse = view(caption, shape=(1, panels), window_size=(400 * panels, 400))
    add_timelapse_3d(lapse.plotter, snapshots, title)
    return lapse
