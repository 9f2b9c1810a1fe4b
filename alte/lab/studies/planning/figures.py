"""Planning figures: paths over each map's occupied cells (top view) and in 3D over the mesh.

Top view: one panel per terrain x mapper; the occupied cells are one
``PolyCollection`` of footprints coloured by cell top (higher cells drawn last), each
policy's path a line, path samples that collide with the true mesh red dots.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from alte.lab.plot.arrays import Floats, polygons
from alte.lab.plot.figure import Caption, Plot, View
from alte.lab.plot.render import view
from alte.lab.studies.planning.experiment import TerrainPlans
from alte.lab.studies.planning.score import densify

if TYPE_CHECKING:
    import pyvista as pv
    from matplotlib.axes import Axes
    from matplotlib.collections import PolyCollection

__all__ = ["POLICY_COLORS", "add_plans_3d", "plans_view", "plot_plans"]

PATHS = Caption("Paths over the maps (top view)",
                "Occupied cells by height; a line per policy; red dots: path samples "
                "too close to the true mesh or inside a solid.")
PATHS_3D = Caption("Paths in 3D", "The planned paths over one terrain's map.")

#: Line colour per unknown-space policy.
POLICY_COLORS = {"free": "tab:orange", "occupied": "tab:blue"}
_SIGNS = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]], dtype=np.float64)


def _footprints(ax: Axes, centers: Floats, sizes: Floats,
                vmax: float) -> PolyCollection:
    from matplotlib.collections import PolyCollection

    top = centers[:, 2] + sizes[:, 2] / 2
    order = np.argsort(top)
    verts = centers[order, None, :2] + _SIGNS[None] * sizes[order, None, :2] / 2
    coll = PolyCollection(polygons(verts), array=top[order], cmap="Greys", clim=(0.0, vmax),
                          edgecolors="none")
    ax.add_collection(coll)
    return coll


def _collisions(plans: TerrainPlans, path: Floats) -> Floats:
    if plans.surface is None or len(path) < 2:
        return np.empty((0, 3))
    samples, _ = densify(path, max(plans.case.clearance / 4, 1e-3))
    bad = plans.surface.inside(samples) | (plans.surface.distance(samples)
                                           < plans.case.clearance)
    colliding: Floats = samples[bad]
    return colliding


def _panel(ax: Axes, plans: TerrainPlans, mapper: str) -> None:
    box = plans.case.box
    centers, sizes = plans.occupied[mapper]
    _footprints(ax, centers, sizes, float(box[1, 2]))
    notes = []
    for (name, policy), res in plans.results.items():
        if name != mapper:
            continue
        notes.append(f"{policy}: {res.status}")
        if res.found:
            ax.plot(res.path[:, 0], res.path[:, 1], color=POLICY_COLORS.get(policy, "k"),
                    lw=1.6, label=f"unknown={policy} ({res.length_m:.1f} m)")
            hits = _collisions(plans, res.path)
            ax.plot(hits[:, 0], hits[:, 1], "r.", ms=3)
    ax.plot(*plans.case.start[:2], "g^", ms=8)
    ax.plot(*plans.case.goal[:2], "r*", ms=10)
    ax.set_xlim(box[0, 0], box[1, 0])
    ax.set_ylim(box[0, 1], box[1, 1])
    ax.set_aspect("equal")
    ax.set_title(f"{plans.terrain} / {mapper}\n" + ", ".join(notes), fontsize=8)
    if any(not str(line.get_label()).startswith("_") for line in ax.get_lines()):
        ax.legend(fontsize=7, loc="lower right")


def plot_plans(plans: Sequence[TerrainPlans], panel_size: float = 4.0) -> Plot:
    """Top views: one row per terrain, one column per mapper; returns the figure."""
    import matplotlib.pyplot as plt

    mappers = list(dict.fromkeys(m for p in plans for m in p.occupied))
    fig, axes = plt.subplots(len(plans), max(len(mappers), 1), squeeze=False,
                             figsize=(panel_size * max(len(mappers), 1),
                                      panel_size * 0.85 * len(plans)))
    for row, terrain_plans in zip(axes, plans, strict=True):
        for ax, mapper in zip(row, mappers, strict=True):
            if mapper in terrain_plans.occupied:
                _panel(ax, terrain_plans, mapper)
            else:
                ax.set_visible(False)
    fig.tight_layout()
    return Plot(fig, PATHS)


def add_plans_3d(plotter: pv.Plotter, plans: TerrainPlans, mapper: str,
                 opacity: float = 0.5) -> pv.Plotter:
    """The true mesh (clipped to the planning domain) and ``mapper``'s paths, start and goal."""
    import pyvista as pv

    if plans.surface is not None:
        surface = plans.surface
        faces = np.hstack([np.full((len(surface.triangles), 1), 3),
                           surface.triangles]).reshape(-1)
        mesh = pv.PolyData(surface.vertices, faces).clip_box(
            plans.case.box.T.reshape(-1).tolist(), invert=False)
        plotter.add_mesh(mesh, color="lightgrey", opacity=opacity)
    for (name, policy), res in plans.results.items():
        if name == mapper and res.found:
            plotter.add_mesh(pv.lines_from_points(res.path), color=POLICY_COLORS.get(policy, "k"),
                             line_width=4, label=f"unknown={policy}")
    radius = 2 * plans.case.step
    plotter.add_mesh(pv.Sphere(radius, plans.case.start), color="green")
    plotter.add_mesh(pv.Sphere(radius, plans.case.goal), color="red")
    return plotter


def plans_view(plans: TerrainPlans, mapper: str) -> View:
    """``mapper``'s paths over the true mesh of one terrain (:func:`add_plans_3d`)."""
    paths = view(PATHS_3D)
    add_plans_3d(paths.plotter, plans, mapper)
    return paths
