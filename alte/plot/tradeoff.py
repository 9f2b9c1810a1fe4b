"""Trade-off figures: size against error per mapper (the field's classic figure), and the
mappers compared at equal size and at equal fidelity.

:func:`tradeoff_figure` draws, per terrain panel, every map as a faint dot (one per
setting and seed), each mapper's Pareto front as its mean over seeds (read at common
sizes, see :mod:`alte.studies.tradeoff`) with a shaded 95 % bootstrap band over seeds,
and a star at the thesis' chosen setting. Size is on a log axis.
"""

from __future__ import annotations

import os
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from alte.errors import ParameterError
from alte.studies.tradeoff import (
    MAPPER_NAMES,
    equal_fidelity,
    equal_size,
    fronts,
    interval_table,
    label,
    matching,
    prepare,
    thesis_setting,
)
from alte.studies.uncertainty import bootstrap_columns

__all__ = ["COLORS", "CURVES", "PAIRS", "equal_fidelity_figure", "equal_size_figure",
           "save_figures", "save_tradeoff_figures", "tradeoff_figure"]

#: One colour per mapper, the same in every figure.
COLORS = {"quadtree": "tab:blue", "alte2d": "tab:orange", "octomap": "tab:green",
          "alte3d": "tab:red"}
_GRID_POINTS = 25


def panels(count: int, width: float = 4.2, height: float = 3.4) -> tuple[Any, np.ndarray]:
    import matplotlib.pyplot as plt

    cols = min(count, 4)
    rows = -(-count // cols)
    fig, axes = plt.subplots(rows, cols, figsize=(width * cols, height * rows), squeeze=False,
                             layout="constrained")
    for ax in axes.ravel()[count:]:
        ax.set_visible(False)
    return fig, axes.ravel()


def legend(fig: Any) -> None:
    """One legend below the panels with every label once."""
    handles: dict[str, Any] = {}
    for ax in fig.axes:
        for handle, text in zip(*ax.get_legend_handles_labels(), strict=True):
            handles.setdefault(text, handle)
    if handles:
        fig.legend(handles.values(), handles.keys(), loc="outside lower center",
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


def mean_front(ax: Any, rows: pd.DataFrame, mapper: str, axes: tuple[str, str],
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
    color = COLORS.get(mapper)
    ax.plot(grid.columns, mean, color=color, lw=2,
            label=f"{MAPPER_NAMES.get(mapper, mapper)} front")
    ax.fill_between(grid.columns, low, high, color=color, alpha=0.2, lw=0)


def log_axis(metric: str) -> bool:
    """Errors (m) and times (s) span decades over a grid: log axis; shares stay linear."""
    return metric.endswith(("_m", "_s"))


def _thesis_star(ax: Any, rows: pd.DataFrame, mapper: str, axes: tuple[str, str]) -> None:
    setting = thesis_setting(mapper)
    chosen = rows[matching(rows, setting)] if setting else rows.iloc[:0]
    if not chosen.empty:
        ax.plot(chosen[axes[0]].mean(), chosen[axes[1]].mean(), "*", ms=14, mec="k",
                color=COLORS.get(mapper), label=f"{MAPPER_NAMES.get(mapper, mapper)}: "
                "thesis' setting")


def tradeoff_figure(table: pd.DataFrame, metric: str = "mhd_m", *,
                    size: str = "basis_functions", mappers: Sequence[str] | None = None,
                    terrains: Sequence[str] | None = None,
                    higher_is_better: bool = False) -> Any:
    """One panel per terrain: ``metric`` against ``size`` (log) for each mapper, every map
    as a dot, the mean Pareto front over seeds with its bootstrap band, the thesis' setting
    starred."""
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
                ax.scatter(part["x"], part["y"], s=10, alpha=alpha, color=COLORS.get(mapper),
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
    return fig


def _levelpanels(summary: pd.DataFrame, names: Sequence[str], ylabel: str, xlabel: str,
                  title: str) -> Any:
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
                        color=COLORS.get(mapper), label=MAPPER_NAMES.get(mapper, mapper))
        ax.set_xticks(range(len(levels)), [f"{v:,.0f}" if v >= 100 else f"{v:.3g}"
                                           for v in levels])
        ax.set(title=terrain, xlabel=xlabel, ylabel=ylabel)
        ax.grid(alpha=0.3)
    legend(fig)
    fig.suptitle(title)
    return fig


def equal_size_figure(table: pd.DataFrame, mappers: Sequence[str], metric: str = "mhd_m", *,
                      size: str = "basis_functions", levels: Sequence[float] | None = None,
                      higher_is_better: bool = False) -> Any:
    """``metric`` of each mapper read off its front at equal ``size`` (mean over seeds,
    95 % bootstrap interval), one panel per terrain."""
    reads = equal_size(prepare(table), mappers, metric, size=size, levels=levels,
                       higher_is_better=higher_is_better)
    return _levelpanels(interval_table(reads.dropna(subset=["value"])), mappers,
                         label(metric), label(size),
                         f"{label(metric)} at equal {label(size, False)}")


def equal_fidelity_figure(table: pd.DataFrame, mappers: Sequence[str],
                          metric: str = "basis_functions", *, fidelity: str = "mhd_m",
                          levels: Sequence[float] | None = None) -> Any:
    """The ``metric`` (size or time) each mapper needs for equal ``fidelity`` (log axis)."""
    reads = equal_fidelity(prepare(table), mappers, metric, fidelity=fidelity, levels=levels)
    fig = _levelpanels(interval_table(reads.dropna(subset=["value"])), mappers,
                        label(metric), label(fidelity),
                        f"{label(metric)} needed for equal {label(fidelity)}")
    for ax in fig.axes:
        ax.set_yscale("log")
    return fig


#: The front page's trade-off figures: name -> (metric, size, higher is better).
CURVES: dict[str, tuple[str, str, bool]] = {
    "tradeoff_mhd": ("mhd_m", "basis_functions", False),
    "tradeoff_accuracy": ("accuracy_mean_m", "basis_functions", False),
    "tradeoff_completeness": ("completeness", "basis_functions", True),
    "tradeoff_height_rmse": ("height_rmse_m", "basis_functions", False),
    "tradeoff_time": ("elapsed_s", "basis_functions", False),
    "tradeoff_memory": ("mhd_m", "memory_bytes", False),
    "tradeoff_obstacle_recall": ("obstacle_recall", "basis_functions", True),
    "tradeoff_obstacle_precision": ("obstacle_precision", "basis_functions", True),
}
#: Pairs compared at equal size / fidelity: figure suffix -> mappers.
PAIRS = {"2d": ("quadtree", "alte2d"), "3d": ("octomap", "alte3d")}


def _figures(table: pd.DataFrame) -> Iterator[tuple[str, Any]]:
    for name, (metric, size, higher) in CURVES.items():
        if metric in table and table[metric].notna().any():
            rows = table[table[metric].notna()]
            yield name, lambda r=rows, m=metric, s=size, h=higher: tradeoff_figure(
                r, m, size=s, higher_is_better=h)
    for suffix, pair in PAIRS.items():
        yield f"equal_size_{suffix}", lambda p=pair: equal_size_figure(table, p)
        yield f"equal_fidelity_{suffix}", lambda p=pair: equal_fidelity_figure(table, p)


def save_figures(figures: Iterator[tuple[str, Any]], out_dir: str | os.PathLike[str],
                 close: bool = True) -> dict[str, Path | str]:
    """Draw each (name, draw) and save it as ``out_dir/figures/<name>.png``; a figure that
    cannot be drawn (:class:`ParameterError`) is recorded as ``"not drawn: <reason>"``."""
    import matplotlib.pyplot as plt

    from alte.notebook import save_figure

    out: dict[str, Path | str] = {}
    for name, draw in figures:
        try:
            fig = draw()
        except ParameterError as err:
            out[name] = f"not drawn: {err}"
            continue
        out[name] = save_figure(fig, out_dir, name)
        if close:
            plt.close(fig)
    return out


def save_tradeoff_figures(table: pd.DataFrame, out_dir: str | os.PathLike[str], *,
                          close: bool = True) -> dict[str, Path | str]:
    """Draw and save every trade-off figure the front page shows (names as in
    :mod:`alte.report.captions`) as ``out_dir/figures/<name>.png``; returns name -> path,
    or the reason a figure could not be drawn (e.g. a mapper absent from the table).
    ``close=False`` leaves the figures open (a notebook then shows them)."""
    return save_figures(_figures(table), out_dir, close)
