"""Ablation figures: the trade-off curves of a pair of mappers with one thing changed.

:func:`ablation_figure` draws one panel per ablation variant of a grid (rows of
:attr:`alte.lab.studies.tradeoff.grid.Grid.variants`) that changes the pair's maps, and the base
grid
with map size counted as occupied cells; :func:`save_ablation_figures` saves one figure per
pair the thesis compares, on the first ablated terrain of its case.
"""

from __future__ import annotations

import os
from collections.abc import Iterator, Sequence
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from alte.errors import ParameterError
from alte.lab.plot.figure import Caption, Plot
from alte.lab.plot.render import Draw, save_figures
from alte.lab.studies.analysis.tradeoff import fronts, label, prepare
from alte.lab.studies.thesis.numbers import TERRAIN_CASE
from alte.lab.studies.tradeoff.figures import (
    PAIRS,
    legend,
    log_axis,
    mapper_color,
    mean_front,
    panels,
)

if TYPE_CHECKING:
    from matplotlib.axes import Axes

__all__ = ["ABLATIONS", "ablation_figure", "save_ablation_figures"]

_BANDS = "Fronts averaged over seeds with 95 % bootstrap bands."
#: Captions of the ablation figures per pair of mappers (``tradeoff_ablation_<suffix>``).
ABLATIONS = {
    "2d": Caption(
        "2D maps with one thing changed",
        "MHD against basis functions of Quadtree and 2D-ALTE on a landing terrain, one "
        "panel per ablation (base: the grid as specified; domain_data: root cell over "
        "the data; set_b_centers / set_b_occupied: another set B; occupancy_max: "
        "Quadtree's occupancy rule; min_pts_per_leaf: 3D-ALTE only; uav_deskew / "
        "uav_lio: the realistic UAV sensor, recorded poses deskewed or LiDAR-inertial "
        "odometry's poses), and the base grid against occupied cells. " + _BANDS),
    "3d": Caption(
        "3D maps with one thing changed",
        "MHD against basis functions of Octomap and 3D-ALTE on a navigation terrain, one "
        "panel per ablation (see the 2D figure), and the base grid against occupied "
        "cells: Octomap's free leaves and 3D-ALTE's empty ones not counted. " + _BANDS),
}


def _panel(ax: Axes, rows: pd.DataFrame, mappers: Sequence[str], axes: tuple[str, str],
           title: str) -> None:
    size, metric = axes
    for mapper in mappers:
        mine = rows[rows["mapper"] == mapper]
        if mine.empty:
            continue
        dots = fronts(mine, size, metric)
        ax.scatter(dots["x"], dots["y"], s=8, alpha=0.25, color=mapper_color(mapper), lw=0)
        mean_front(ax, mine, mapper, (size, metric), False)
    ax.set_xscale("log")
    ax.set_yscale("log" if log_axis(metric) else "linear")
    ax.set(title=title, xlabel=label(size), ylabel=label(metric))
    ax.grid(alpha=0.3, which="both")


def _same_maps(rows: pd.DataFrame, first: str, other: str, metric: str) -> bool:
    """Whether variant ``other`` gave the same maps as ``first`` (it changed nothing here)."""
    columns = ["basis_functions", metric]
    values = [np.sort(rows[rows["variant"] == n][columns].to_numpy(float), axis=0)
              for n in (first, other)]
    return values[0].shape == values[1].shape and bool(np.allclose(values[0], values[1],
                                                                  equal_nan=True))


def ablation_figure(variants: pd.DataFrame, mappers: Sequence[str], terrain: str,
                    metric: str = "mhd_m", *, caption: Caption | None = None) -> Plot:
    """``metric`` against basis functions of ``mappers`` on ``terrain``, one panel per
    ablation variant (rows of :func:`alte.lab.studies.tradeoff.grid.Grid.variants`, column
    ``variant``) that changes them, plus the base grid with size counted as occupied
    cells (``caption``: see :data:`ABLATIONS`)."""
    rows = prepare(variants[variants["terrain"] == terrain])
    rows = rows[rows["mapper"].isin(mappers) & rows[metric].notna()]
    first = rows["variant"].iloc[0] if len(rows) else ""
    names = [n for n in dict.fromkeys(rows["variant"])
             if n == first or not _same_maps(rows, first, n, metric)]
    if len(names) < 2:
        raise ParameterError(f"no ablation variants of {list(mappers)} on {terrain}")
    fig, axes = panels(len(names) + 1, 3.6, 3.0)
    for ax, name in zip(axes, names, strict=False):
        _panel(ax, rows[rows["variant"] == name], mappers, ("basis_functions", metric), name)
    _panel(axes[len(names)], rows[rows["variant"] == names[0]], mappers,
           ("occupied_cells", metric), f"{names[0]}, size = occupied cells")
    legend(fig)
    title = f"{label(metric)} against map size with one thing changed"
    fig.suptitle(f"{terrain}: {title}")
    return Plot(fig, caption or Caption(title, f"One panel per ablation variant. {_BANDS}"))


def save_ablation_figures(variants: pd.DataFrame, out_dir: str | os.PathLike[str], *,
                          close: bool = True) -> dict[str, Path | str]:
    """:func:`ablation_figure` for each pair of mappers on the first ablated terrain of
    its case, saved as ``tradeoff_ablation_2d``/``_3d`` (see
    :func:`alte.lab.plot.render.save_figures`)."""
    changed = variants[variants["variant"] != variants["variant"].iloc[0]] \
        if len(variants) else variants
    places = sorted(set(changed["terrain"]))
    cases = {"2d": "lan", "3d": "nav"}

    def figures() -> Iterator[tuple[str, Draw]]:
        for suffix, pair in PAIRS.items():
            where = [t for t in places if TERRAIN_CASE.get(t) == cases[suffix]]
            yield f"tradeoff_ablation_{suffix}", partial(
                ablation_figure, variants, pair, where[0] if where else "(no terrain)",
                caption=ABLATIONS[suffix])
    return save_figures(figures(), out_dir, close)
