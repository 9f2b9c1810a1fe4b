"""Trade-off figures: size against error per mapper (the field's classic figure), and the
mappers compared at equal size and at equal fidelity.

:func:`tradeoff_figure` draws, per terrain panel, every map as a faint dot (one per
setting and seed), each mapper's Pareto front as its mean over seeds (read at common
sizes, see :mod:`alte.lab.studies.analysis.tradeoff`) with a shaded 95 % bootstrap band over seeds,
and a star at the thesis' chosen setting. Size is on a log axis.
"""

from __future__ import annotations

import os
import zlib
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from alte.errors import ParameterError
from alte.lab.plot.figure import Caption, Plot
from alte.lab.plot.render import Draw, save_figures
from alte.lab.studies.analysis.tradeoff import (
    equal_fidelity,
    equal_size,
    fronts,
    interval_table,
    label,
    mapper_title,
    matching,
    prepare,
    thesis_setting,
)
from alte.lab.studies.analysis.uncertainty import bootstrap_columns

if TYPE_CHECKING:
    from matplotlib.artist import Artist
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = ["COLORS", "CURVES", "EQUAL_FIDELITY", "EQUAL_SIZE", "FRONT", "PAIRS",
           "TradeoffCurve", "equal_fidelity_figure", "equal_size_figure", "mapper_color",
           "save_tradeoff_figures", "tradeoff_figure"]

#: One colour per mapper, the same in every figure.
COLORS = {"quadtree": "tab:blue", "alte2d": "tab:orange", "octomap": "tab:green",
          "alte3d": "tab:red"}
#: Colours of further mappers (plugins), none of the thesis' four's.
_MORE_COLORS = ("tab:purple", "tab:brown", "tab:pink", "tab:olive", "tab:cyan", "tab:gray")


def mapper_color(mapper: str) -> str:
    """A mapper's colour: the thesis' four's from :data:`COLORS`, any other mapper's picked
    from its name (the same in every figure and run), never one of the four's."""
    return COLORS.get(mapper) or _MORE_COLORS[zlib.crc32(mapper.encode()) % len(_MORE_COLORS)]
_GRID_POINTS = 25


#: How to read a trade-off figure, the end of each one's caption.
FRONT = ("Each dot is one map (a parameter setting and seed); the line is the mapper's Pareto "
         "front (no other of its maps is both smaller and better) averaged over seeds, the "
         "band its 95 % bootstrap interval over seeds; the star marks the thesis' chosen "
         "setting. Size on a log axis, and errors and times too (they span decades over a "
         "grid); completeness on a linear one.")
def panels(count: int, width: float = 4.2, height: float = 3.4) -> tuple[Figure, list[Axes]]:
    import matplotlib.pyplot as plt

    cols = min(count, 4)
    rows = -(-count // cols)
    fig, axes = plt.subplots(rows, cols, figsize=(width * cols, height * rows), squeeze=False,
                             layout="constrained")
    flat: list[Axes] = list(axes.ravel())
    for ax in flat[count:]:
        ax.set_visible(False)
    return fig, flat


def legend(fig: Figure) -> None:
    """One legend below the panels with every label once."""
    handles: dict[str, Artist] = {}
    for ax in fig.axes:
        for handle, text in zip(*ax.get_legend_handles_labels(), strict=True):
            handles.setdefault(text, handle)
    if handles:
        fig.legend(list(handles.values()), list(handles.keys()), loc="outside lower center",
                   ncols=min(len(handles), 4), fontsize=8)


def _select(table: pd.DataFrame, mappers: Sequence[str] | None,
            terrains: Sequence[str] | None) -> tuple[pd.DataFrame, list[str], list[str]]:
    names = list(dict.fromkeys(table["mapper"])) if mappers is None else list(mappers)
    places = sorted(set(table["terrain"])) if terrains is None else list(terrains)
    rows = table[table["mapper"].isin(names) & table["terrain"].isin(places)]
    if rows.empty:
        raise ParameterError(f"trade-off table: no rows of {names} on {places}")
    present = set(rows["terrain"])
    return rows, [m for m in names if m in set(rows["mapper"])], [t for t in places
                                                                  if t in present]


def mean_front(ax: Axes, rows: pd.DataFrame, mapper: str, axes: tuple[str, str],
                higher_is_better: bool) -> None:
    """The mean front over seeds, read at sizes every seed's maps span, with its band."""
    size, metric = axes
    x = rows[size].to_numpy(float)
    x = x[np.isfinite(x) & (x > 0)]
    if x.size == 0:
        return
    reads = equal_size(rows, (mapper,), metric, size=size,
                       levels=np.geomspace(x.min(), x.max(), _GRID_POINTS),
                       higher_is_better=higher_is_better)
    grid = reads.pivot_table(index="seed", columns="level", values="value", dropna=False)
    grid = grid.loc[:, grid.notna().all(axis=0)]
    if grid.empty:
        return
    mean, low, high = bootstrap_columns(grid.to_numpy())
    color = mapper_color(mapper)
    ax.plot(grid.columns, mean, color=color, lw=2,
            label=f"{mapper_title(mapper)} front")
    ax.fill_between(grid.columns, low, high, color=color, alpha=0.2, lw=0)


def log_axis(metric: str) -> bool:
    """Errors (m) and times (s) span decades over a grid: log axis; shares stay linear."""
    return metric.endswith(("_m", "_s"))


def _thesis_star(ax: Axes, rows: pd.DataFrame, mapper: str, axes: tuple[str, str]) -> None:
    setting = thesis_setting(mapper)
    chosen = rows[matching(rows, setting)] if setting else rows.iloc[:0]
    if not chosen.empty:
        ax.plot(chosen[axes[0]].mean(), chosen[axes[1]].mean(), "*", ms=14, mec="k",
                color=mapper_color(mapper), label=f"{mapper_title(mapper)}: "
                "thesis' setting")


def tradeoff_figure(table: pd.DataFrame, metric: str = "mhd_m", *,
                    size: str = "basis_functions", mappers: Sequence[str] | None = None,
                    terrains: Sequence[str] | None = None,
                    higher_is_better: bool = False, caption: Caption | None = None) -> Plot:
    """One panel per terrain: ``metric`` against ``size`` (log) for each mapper, every map
    as a dot, the mean Pareto front over seeds with its bootstrap band, the thesis' setting
    starred (``caption``: by default how to read it, see :data:`CURVES` for the page's)."""
    rows, names, places = _select(prepare(table), mappers, terrains)
    fig, axes = panels(len(places))
    for ax, terrain in zip(axes, places, strict=False):
        here = rows[rows["terrain"] == terrain]
        for mapper in names:
            mine = here[here["mapper"] == mapper]
            if mine.empty:
                continue
            dots = fronts(mine, size, metric, higher_is_better)
            for on, alpha in ((False, 0.25), (True, 0.7)):
                part = dots[dots["on_front"] == on]
                ax.scatter(part["x"], part["y"], s=10, alpha=alpha, color=mapper_color(mapper),
                           lw=0)
            mean_front(ax, mine, mapper, (size, metric), higher_is_better)
            _thesis_star(ax, mine, mapper, (size, metric))
        ax.set_xscale("log")
        ax.set_yscale("log" if log_axis(metric) else "linear")
        ax.set(title=terrain, xlabel=label(size), ylabel=label(metric))
        ax.grid(alpha=0.3, which="both")
    legend(fig)
    seeds = rows["seed"].nunique()
    fig.suptitle(f"{label(metric)} against {label(size)}: Pareto fronts, mean over {seeds} "
                 f"seed{'s' if seeds != 1 else ''} with 95 % bootstrap band")
    return Plot(fig, caption or Caption(f"{label(metric, False)} against {label(size, False)}",
                                        FRONT))


def _levelpanels(summary: pd.DataFrame, names: Sequence[str], ylabel: str, xlabel: str,
                  title: str) -> Figure:
    places = sorted(set(summary["terrain"]))
    if not places:
        raise ParameterError("no terrain has every mapper over a common range to compare")
    fig, axes = panels(len(places), 4.0, 3.2)
    for ax, terrain in zip(axes, places, strict=False):
        part = summary[summary["terrain"] == terrain]
        levels = sorted(set(part["level"]))
        for k, mapper in enumerate(names):
            mine = part[part["mapper"] == mapper].set_index("level").reindex(levels)
            pos = np.arange(len(levels)) + (k - (len(names) - 1) / 2) * 0.15
            err = np.vstack([mine["mean"] - mine["low"], mine["high"] - mine["mean"]])
            ax.errorbar(pos, mine["mean"], yerr=err, fmt="o", capsize=3,
                        color=mapper_color(mapper), label=mapper_title(mapper))
        ax.set_xticks(range(len(levels)), [f"{v:,.0f}" if v >= 100 else f"{v:.3g}"
                                           for v in levels])
        ax.set(title=terrain, xlabel=xlabel, ylabel=ylabel)
        ax.grid(alpha=0.3)
    legend(fig)
    fig.suptitle(title)
    return fig


def equal_size_figure(table: pd.DataFrame, mappers: Sequence[str], metric: str = "mhd_m", *,
                      size: str = "basis_functions", levels: Sequence[float] | None = None,
                      higher_is_better: bool = False, caption: Caption | None = None) -> Plot:
    """``metric`` of each mapper read off its front at equal ``size`` (mean over seeds,
    95 % bootstrap interval), one panel per terrain (``caption``: see :data:`EQUAL_SIZE`)."""
    reads = equal_size(prepare(table), mappers, metric, size=size, levels=levels,
                       higher_is_better=higher_is_better)
    title = f"{label(metric)} at equal {label(size, False)}"
    fig = _levelpanels(interval_table(reads.dropna(subset=["value"])), mappers,
                       label(metric), label(size), title)
    return Plot(fig, caption or Caption(title, _READ))


def equal_fidelity_figure(table: pd.DataFrame, mappers: Sequence[str],
                          metric: str = "basis_functions", *, fidelity: str = "mhd_m",
                          levels: Sequence[float] | None = None,
                          caption: Caption | None = None) -> Plot:
    """The ``metric`` (size or time) each mapper needs for equal ``fidelity`` (log axis;
    ``caption``: see :data:`EQUAL_FIDELITY`)."""
    reads = equal_fidelity(prepare(table), mappers, metric, fidelity=fidelity, levels=levels)
    title = f"{label(metric)} needed for equal {label(fidelity)}"
    fig = _levelpanels(interval_table(reads.dropna(subset=["value"])), mappers,
                       label(metric), label(fidelity), title)
    for ax in fig.axes:
        ax.set_yscale("log")
    return Plot(fig, caption or Caption(title, _READ + " Log axis."))


_READ = "Read off each mapper's front; mean over seeds with 95 % bootstrap intervals."


@dataclass(frozen=True)
class TradeoffCurve:
    """A front-page trade-off figure: ``metric`` against ``size``, and its caption."""

    metric: str
    size: str
    higher_is_better: bool
    caption: Caption


#: The front page's trade-off figures by name.
CURVES: dict[str, TradeoffCurve] = {
    "tradeoff_mhd": TradeoffCurve("mhd_m", "basis_functions", False,
                                  Caption("MHD against map size", FRONT)),
    "tradeoff_accuracy": TradeoffCurve(
        "accuracy_mean_m", "basis_functions", False,
        Caption("Mean accuracy against map size", "Ground-truth accuracy (distance of each "
                "occupied cell to the true surface). " + FRONT)),
    "tradeoff_completeness": TradeoffCurve(
        "completeness", "basis_functions", True,
        Caption("Completeness against map size", "Share of the true surface the map covers "
                "(higher is better: the front is the upper-left envelope). " + FRONT)),
    "tradeoff_height_rmse": TradeoffCurve(
        "height_rmse_m", "basis_functions", False,
        Caption("Height RMSE against map size (2D maps)",
                "RMSE of the map height against the true top surface. " + FRONT)),
    "tradeoff_time": TradeoffCurve(
        "elapsed_s", "basis_functions", False,
        Caption("Mapping time against map size", "Time spent in the mapper calls only. "
                + FRONT)),
    "tradeoff_memory": TradeoffCurve("mhd_m", "memory_bytes", False,
                                     Caption("MHD against memory", FRONT)),
    "tradeoff_obstacle_recall": TradeoffCurve(
        "obstacle_recall", "basis_functions", True,
        Caption("Obstacle recall against map size",
                "Share of the true obstacles the map shows (simulator objects standing at "
                "least the landing study's obstacle step above the ground, 0.3 m at urban "
                "scale and 0.06 m in the lab, seen from above; higher is better). " + FRONT)),
    "tradeoff_obstacle_precision": TradeoffCurve(
        "obstacle_precision", "basis_functions", True,
        Caption("Obstacle precision against map size",
                "Share of the map's obstacles (connected areas more than that step above its "
                "ground) that lie on a true object (higher is better). " + FRONT)),
}
#: Pairs compared at equal size / fidelity: figure suffix -> mappers.
PAIRS = {"2d": ("quadtree", "alte2d"), "3d": ("octomap", "alte3d")}
#: Captions of the pairs' equal-size figures (``equal_size_<suffix>``).
EQUAL_SIZE = {s: Caption(f"{s.upper()} maps at equal size",
                         f"MHD each {s.upper()} mapper reaches at the same number of basis "
                         "functions, read off its front; mean over seeds with 95 % bootstrap "
                         "intervals.") for s in PAIRS}
#: Captions of the pairs' equal-fidelity figures (``equal_fidelity_<suffix>``).
EQUAL_FIDELITY = {s: Caption(f"{s.upper()} maps at equal fidelity",
                             f"Basis functions each {s.upper()} mapper needs for the same MHD "
                             "(log axis); mean over seeds with 95 % bootstrap intervals.")
                  for s in PAIRS}


def _figures(table: pd.DataFrame) -> Iterator[tuple[str, Draw]]:
    for name, curve in CURVES.items():
        if curve.metric in table and table[curve.metric].notna().any():
            yield name, partial(tradeoff_figure, table[table[curve.metric].notna()],
                                curve.metric, size=curve.size,
                                higher_is_better=curve.higher_is_better, caption=curve.caption)
    for suffix, pair in PAIRS.items():
        yield f"equal_size_{suffix}", partial(equal_size_figure, table, pair,
                                              caption=EQUAL_SIZE[suffix])
        yield f"equal_fidelity_{suffix}", partial(equal_fidelity_figure, table, pair,
                                                  caption=EQUAL_FIDELITY[suffix])


def save_tradeoff_figures(table: pd.DataFrame, out_dir: str | os.PathLike[str], *,
                          close: bool = True, jobs: int = 1) -> dict[str, Path | str]:
    """Draw and save every trade-off figure the front page shows (:data:`CURVES`, the
    pairs at equal size and fidelity) as ``out_dir/figures/<name>.png``; returns name -> path,
    or the reason a figure could not be drawn (e.g. a mapper absent from the table).
    ``close=False`` leaves the figures open (a notebook then shows them); ``jobs > 1``
    draws them in that many processes (:func:`~alte.lab.plot.render.save_figures`)."""
    return save_figures(_figures(table), out_dir, close, jobs=jobs)
