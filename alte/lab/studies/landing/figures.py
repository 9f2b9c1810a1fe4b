"""Landing-site figures: the map raster with obstacles, feasible areas and chosen sites.

Every layer is one artist (an image, a contour set, one circle collection), so a
280 x 280 raster with many sites draws at once. Unknown pixels are grey, never drawn
like ground. Chosen sites are circles of the disk that must be clear (radius +
margin), numbered by rank, green when truly safe and red when not (grey without
ground truth).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from alte.errors import ParameterError
from alte.lab.plot.arrays import Floats
from alte.lab.plot.figure import Caption, Plot
from alte.lab.studies.landing.detect import Centres, Detection
from alte.lab.studies.landing.experiment import LandingRun
from alte.lab.studies.landing.params import LandingSettings

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.image import AxesImage

__all__ = ["plot_landing", "plot_landing_runs"]

LANDING_SITES = Caption(
    "Landing sites on the maps",
    "Map height (grey: unknown), obstacles red, detected feasible centres inside the "
    "blue outline, truly feasible ones inside the dashed green one; circles are the "
    "chosen sites, green when truly safe and red when not.")

_UNKNOWN = (0.8, 0.8, 0.8, 1.0)


def _site_colours(detection: Detection, truth: Centres | None) -> Floats:
    chosen = detection.chosen
    if truth is None or not len(chosen):
        return np.tile([0.5, 0.5, 0.5, 1.0], (len(chosen), 1))
    rc = detection.grid.index(chosen[["x", "y"]].to_numpy())
    safe = truth.feasible[rc[:, 0], rc[:, 1]]
    return np.where(safe[:, None], [0.0, 0.6, 0.0, 1.0], [0.85, 0.0, 0.0, 1.0])


def plot_landing(detection: Detection, params: LandingSettings, ax: Axes, *,
                 truth: Centres | None = None, title: str | None = None) -> AxesImage:
    """Draw one detection on ``ax``: heights, obstacles (red), detected feasible centres
    (blue outline), truly feasible centres (green dashed) and the chosen sites."""
    import matplotlib as mpl
    from matplotlib.collections import EllipseCollection

    grid = detection.grid
    cmap = mpl.colormaps["viridis"].with_extremes(bad=_UNKNOWN)
    image = ax.imshow(np.ma.masked_invalid(detection.height), origin="lower",
                      extent=grid.extent, cmap=cmap, interpolation="nearest")
    ax.figure.colorbar(image, ax=ax, label="map height [m]", shrink=0.8)
    red = mpl.colors.ListedColormap([(0, 0, 0, 0), (0.9, 0.1, 0.1, 0.8)])
    ax.imshow(detection.centres.obstacle.astype(float), origin="lower", extent=grid.extent,
              cmap=red, vmin=0, vmax=1, interpolation="nearest")
    xs, ys = grid.axes()
    for mask, colour, line in ((detection.centres.feasible, "tab:blue", "solid"),
                               (None if truth is None else truth.feasible, "lime", "dashed")):
        if mask is not None and mask.any() and not mask.all():
            ax.contour(xs, ys, mask.astype(float), levels=[0.5], linewidths=1.0, colors=colour,
                       linestyles=line)
    chosen = detection.chosen
    xy = chosen[["x", "y"]].to_numpy()
    diameter = np.full(len(xy), 2 * params.disk)
    ax.add_collection(EllipseCollection(diameter, diameter, 0.0, units="xy", offsets=xy,
                                        offset_transform=ax.transData, facecolors="none",
                                        edgecolors=_site_colours(detection, truth),
                                        linewidths=2.0))
    for rank, (x, y) in zip(chosen["rank"], xy, strict=True):  # at most max_sites labels
        ax.annotate(str(rank), (x, y), ha="center", va="center", fontsize=8, weight="bold")
    ax.set_xlim(grid.extent[:2])
    ax.set_ylim(grid.extent[2:])
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    if title:
        ax.set_title(title, fontsize=9)
    return image


def plot_landing_runs(runs: Sequence[LandingRun], ncols: int = 2, panel_size: float = 4.5,
                      only: str | None = None) -> Plot:
    """A figure with one :func:`plot_landing` panel per run, titled with its scores.

    ``only`` keeps the runs whose label starts with it (e.g. ``"ch4"``).
    """
    import matplotlib.pyplot as plt

    runs = [r for r in runs if only is None or r.label.startswith(only)]
    if not runs:
        raise ParameterError(f"plot_landing_runs: no runs to draw (only={only!r})")
    nrows = -(-len(runs) // ncols)
    fig, axes = plt.subplots(nrows, ncols, figsize=(ncols * panel_size * 1.15,
                                                    nrows * panel_size), squeeze=False)
    for ax, run in zip(axes.flat, runs, strict=False):
        s = run.scores
        title = (f"{run.terrain} {run.map_run.info.mapper} ({run.label})\n"
                 f"precision {s.get('precision', np.nan):.2f}, "
                 f"recall {s.get('recall', np.nan):.2f}")
        plot_landing(run.detection, run.landing, ax, truth=run.truth, title=title)
    for ax in axes.flat[len(runs):]:
        ax.set_visible(False)
    fig.tight_layout()
    return Plot(fig, LANDING_SITES)
