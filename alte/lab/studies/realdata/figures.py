"""Chapter-6 figures; each accepts the empty runs of a skipped chapter and then draws nothing.

:func:`ground_figure` shows every ISPRS sample x filter from above, each point
coloured by its outcome against the reference (ground kept, object removed, type I,
type II); :func:`fronts_figure` draws the real sequence's fronts (size against MHD and
against the distance to the reference cloud, per pair of mappers); :func:`maps_view`
puts 3D maps side by side in one pyvista plotter, which :func:`show_maps` saves and shows
(a PNG headless, trame in JupyterLab); :func:`poses_figure` draws table 6.4, every pose
source on every real sequence.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.colors import ListedColormap
from matplotlib.figure import Figure

from alte.lab.plot.arrays import Bools, Ints
from alte.lab.plot.figure import Caption, Plot, View
from alte.lab.plot.render import save_figure as _save_figure
from alte.lab.plot.render import show, view
from alte.lab.studies.experiments import Measured
from alte.lab.studies.realdata.data import GroundRun

__all__ = ["FRONT_PANELS", "OUTCOMES", "POSE_PANELS", "SCAN_MAPS", "VLP16_MAPS",
           "fronts_figure", "ground_figure", "maps_view", "outcomes", "poses_figure",
           "save_figure", "show_maps"]

GROUND_FILTER = Caption("Ground filter (fig. 6.1)", "Ground filter errors on the ISPRS samples.")
REAL_FRONTS = Caption(
    "The fronts on a real sequence (balm_seq)",
    "Real scans mapped with their reference poses (bundle adjustment): every map one "
    "dot, the line each mapper's Pareto front (one recording: no seeds, no band). "
    "MHD is the thesis' metric against the cloud the map was made from; height RMSE, "
    "mean accuracy and completeness are measured against the reference cloud (every "
    "scan with its reference pose), the real stand-in for the simulator's truth.")
REAL_POSES = Caption(
    "Poses on real sequences (fig. 6.4)",
    "Every pose source on each real sequence, against the sequence's reference poses "
    "(bundle adjustment): the registered cloud's median distance to the cloud registered "
    "with the reference poses (as the pipeline placed it), the ATE after rigid alignment "
    "and the pose step's CPU time per scan. Recorded poses are the reference (ATE 0, no "
    "pose step); log axes, zero drawn at the floor.")
#: The 3D maps of the OctoMap scan (:func:`maps_view`).
SCAN_MAPS = Caption("3D maps of the OctoMap scan (fig. 6.2)",
                    "Occupied cells of each 3D map of the real OctoMap scan (scan.dat, one "
                    "scan, sensor at the origin), coloured by height, side by side.")
#: The 3D maps of the VLP-16 packet bag (:func:`maps_view`).
VLP16_MAPS = Caption("3D maps of the VLP-16 bag (fig. 6.3)",
                     "Occupied cells of each 3D map of the decoded VLP-16 packet bag "
                     "(stationary sensor, identity pose), coloured by height, side by side.")

#: Outcome classes of a ground filter, in the order of :func:`outcomes`' codes.
OUTCOMES = ("ground kept", "object removed", "type I (ground removed)",
            "type II (object kept)")
_COLORS = ListedColormap(["#c8b28a", "#9aa7b1", "#1f5fd6", "#e0241b"])
_MAX_DOTS = 40_000


def outcomes(ground: Bools, reference: Bools) -> Ints:
    """Per point: 0 ground kept, 1 object removed, 2 type I error, 3 type II error."""
    ground, reference = np.asarray(ground, bool), np.asarray(reference, bool)
    return np.select([reference & ground, ~reference & ~ground, reference & ~ground],
                     [0, 1, 2], default=3)


def ground_figure(runs: Sequence[GroundRun]) -> Plot | None:
    """Top views, one row per sample, one column per filter (None for no runs)."""
    if not runs:
        return None
    samples = list(dict.fromkeys(r.sample for r in runs))
    filters = list(dict.fromkeys(r.mapper_name for r in runs))
    fig = Figure(figsize=(3.6 * len(filters), 3.4 * len(samples)), layout="constrained")
    axes = np.asarray(fig.subplots(len(samples), len(filters), squeeze=False))
    for run in runs:
        ax = axes[samples.index(run.sample), filters.index(run.mapper_name)]
        step = max(1, len(run.points) // _MAX_DOTS)
        code = outcomes(run.ground, run.reference)[::step]
        xy = run.points[::step, :2]
        order = np.argsort(code, kind="stable")  # errors drawn on top
        ax.scatter(xy[order, 0], xy[order, 1], c=code[order], cmap=_COLORS, vmin=0, vmax=3,
                   s=0.4, rasterized=True)
        ax.set_aspect("equal")
        ax.set_title(f"{run.sample} {run.mapper_name}: total {run.metrics['total_pct']:.1f}%",
                     fontsize=9)
        ax.tick_params(labelsize=7)
    handles = [ax.scatter([], [], color=_COLORS(i), label=name)
               for i, name in enumerate(OUTCOMES)]
    fig.legend(handles=handles, loc="outside lower center", ncol=4, fontsize=8)
    return Plot(fig, GROUND_FILTER)


def save_figure(item: Plot | View | None, out_dir: str | os.PathLike[str],
                name: str) -> Path | None:
    """:func:`alte.lab.plot.render.save_figure`, or nothing for a skipped figure (None)."""
    return None if item is None else _save_figure(item, out_dir, name)


def maps_view(runs: Sequence[Measured], title: str = "", *, caption: Caption) -> View | None:
    """Occupied cells of each map side by side (linked cameras; ``caption``:
    :data:`SCAN_MAPS` or :data:`VLP16_MAPS`); None for no runs."""
    if not runs:
        return None
    from alte.lab.plot.maps import add_cells_3d

    maps = view(caption, shape=(1, len(runs)), window_size=(480 * len(runs), 480))
    plotter = maps.plotter
    for i, run in enumerate(runs):
        plotter.subplot(0, i)
        add_cells_3d(plotter, run.mapper.cells(), show_edges=False,
                     scalar_bar_args={"title": f"height {i} [m]"})
        plotter.add_text(f"{title} {run.name}: {run.metrics.occupied_cells} occupied",
                         font_size=9)
    plotter.link_views()
    return maps


def show_maps(runs: Sequence[Measured], out_dir: str | os.PathLike[str] | None = None,
              name: str | None = None, title: str = "", *, caption: Caption) -> None:
    """:func:`maps_view`, saved as ``out_dir/figures/name.png`` (and shown) when both are
    given, else only shown; nothing for no runs."""
    maps = maps_view(runs, title, caption=caption)
    if maps is not None:
        show(maps, out_dir, name)


#: Panels of :func:`fronts_figure`: (mappers, metric, higher is better).
FRONT_PANELS: tuple[tuple[tuple[str, str], str, bool], ...] = (
    (("quadtree", "alte2d"), "mhd_m", False), (("quadtree", "alte2d"), "height_rmse_m", False),
    (("octomap", "alte3d"), "mhd_m", False), (("octomap", "alte3d"), "accuracy_mean_m", False),
    (("octomap", "alte3d"), "completeness", True))


def fronts_figure(table: pd.DataFrame) -> Plot | None:
    """The real sequence's maps, one dot each, and each mapper's Pareto front, per panel of
    :data:`FRONT_PANELS` (size on a log axis); None for an empty table."""
    if table.empty:
        return None
    from alte.lab.studies.analysis.tradeoff import fronts, label, mapper_title
    from alte.lab.studies.tradeoff.figures import log_axis, mapper_color

    fig = Figure(figsize=(4.0 * len(FRONT_PANELS), 3.6), layout="constrained")
    axes = np.asarray(fig.subplots(1, len(FRONT_PANELS), squeeze=False)).ravel()
    for ax, (pair, metric, higher) in zip(axes, FRONT_PANELS, strict=True):
        rows = table[table["mapper"].isin(pair) & table[metric].notna()]
        for mapper in pair:
            dots = fronts(rows[rows["mapper"] == mapper], "basis_functions", metric, higher)
            name = mapper_title(mapper)
            ax.scatter(dots["x"], dots["y"], s=14, alpha=0.5, color=mapper_color(mapper), lw=0)
            line = dots[dots["on_front"]].sort_values("x")
            ax.plot(line["x"], line["y"], color=mapper_color(mapper), lw=2, label=name)
        ax.set_xscale("log")
        ax.set_yscale("log" if log_axis(metric) else "linear")
        against = "the cloud mapped" if metric.startswith(("mhd", "hd")) else "the reference"
        ax.set(xlabel=label("basis_functions"), ylabel=label(metric),
               title=f"{label(metric, False)} against {against}")
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=8)
    name = str(table["terrain"].iloc[0])
    fig.suptitle(f"{name}: real scans with reference poses, {int(table['frames'].iloc[0])} "
                 f"scans mapped, {int(table['reference_points'].iloc[0]):,} reference points")
    return Plot(fig, REAL_FRONTS)


#: Panels of :func:`poses_figure`: (column, label, factor to the unit shown).
POSE_PANELS: tuple[tuple[str, str, float], ...] = (
    ("cloud_median_m", "cloud to reference cloud, median [mm]", 1e3),
    ("ate_m", "ATE [mm]", 1e3), ("cpu_ms_per_scan", "CPU per scan [ms]", 1.0))
#: Where a zero is drawn on the log axes of :func:`poses_figure`.
_FLOOR = 1e-2


def poses_figure(table: pd.DataFrame) -> Plot | None:
    """Table 6.4 as grouped bars, one group per sequence and one bar per pose source, a
    panel per :data:`POSE_PANELS` column; None for an empty table."""
    if table.empty:
        return None
    inputs = list(dict.fromkeys(table["input"]))
    sources = list(dict.fromkeys(table["source"]))
    width = 0.8 / len(sources)
    fig = Figure(figsize=(4.2 * len(POSE_PANELS), 3.6), layout="constrained")
    axes = np.asarray(fig.subplots(1, len(POSE_PANELS), squeeze=False)).ravel()
    for ax, (column, label, factor) in zip(axes, POSE_PANELS, strict=True):
        for k, source in enumerate(sources):
            rows = table[table["source"] == source].set_index("input").reindex(inputs)
            values = np.maximum(rows[column].to_numpy(dtype=float) * factor, _FLOOR)
            ax.bar(np.arange(len(inputs)) + (k - (len(sources) - 1) / 2) * width, values,
                   width, label=source)
        ax.set_yscale("log")
        ax.set_xticks(np.arange(len(inputs)), inputs)
        ax.set(ylabel=label, title=label.split(" [")[0])
        ax.grid(alpha=0.3, axis="y", which="both")
    axes[0].legend(fontsize=8)
    return Plot(fig, REAL_POSES)
