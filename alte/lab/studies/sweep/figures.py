"""Sweep figures: sensitivity surfaces (heatmap + contours) and main-effect curves.

Grid axes are drawn by level index with the parameter values as tick labels, so
log-spaced values (``kappa`` 0.01, 0.1, 1) are evenly spaced as they were swept.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from alte.errors import ParameterError
from alte.lab.plot.figure import Caption, Plot
from alte.lab.studies.analysis.tradeoff import mapper_title
from alte.lab.studies.sweep.analysis import (
    main_effects,
    mapper_rows,
    param_columns,
    sensitivity_table,
)

if TYPE_CHECKING:
    from matplotlib.axes import Axes

__all__ = ["effects_figure", "sensitivity_figure"]

MAIN_EFFECTS = Caption("Main effects", "Each metric's mean at each level of each swept parameter.")

#: Axis labels of the usual metrics (others are shown by column name).
LABELS = {"mhd_m": "MHD (m)", "hd_m": "HD (m)", "basis_functions": "basis functions",
          "elapsed_s": "mapping time (s)", "completeness": "completeness",
          "accuracy_mean_m": "mean accuracy (m)", "memory_bytes": "memory (bytes)"}


def _label(value: object) -> str:
    return f"{value:g}" if isinstance(value, float | np.floating) else str(value)


def _number(value: float) -> str:
    if not np.isfinite(value):
        return "-"
    return f"{value:.0f}" if abs(value) >= 1000 else f"{value:.3g}"


def _heatmap(ax: Axes, grid: pd.DataFrame, metric: str) -> None:
    values = grid.to_numpy(dtype=float)
    image = ax.imshow(values, origin="lower", aspect="auto", cmap="viridis")
    ax.figure.colorbar(image, ax=ax, label=LABELS.get(metric, metric))
    finite = values[np.isfinite(values)]
    if min(values.shape) > 1 and finite.size and np.ptp(finite) > 0:
        ax.contour(values, levels=5, colors="white", linewidths=0.7, alpha=0.8)
    shades = np.asarray(image.norm(values), dtype=float)
    for (r, c), v in np.ndenumerate(values):
        light = bool(np.isfinite(v) and shades[r, c] > 0.6)  # dark text on the yellow end
        ax.text(c, r, _number(float(v)), ha="center", va="center", fontsize=7,
                color="k" if light else "w")
    ax.set_xticks(range(values.shape[1]), [_label(v) for v in grid.columns])
    ax.set_yticks(range(values.shape[0]), [_label(v) for v in grid.index])
    ax.set_xlabel("" if grid.columns.name is None else str(grid.columns.name))
    ax.set_ylabel("" if grid.index.name is None else str(grid.index.name))
    ax.set_title(LABELS.get(metric, metric))


def sensitivity_figure(table: pd.DataFrame, mapper: str, x: str, y: str,
                       metrics: Sequence[str], *, terrain: str | None = None,
                       fixed: Mapping[str, object] | None = None) -> Plot:
    """One heatmap per metric over parameters ``x`` and ``y`` (mean over other parameters),
    captioned with the mapper and the two parameters."""
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(metrics), figsize=(4.6 * len(metrics), 3.6),
                             squeeze=False, layout="constrained")
    for ax, metric in zip(axes[0], metrics, strict=True):
        grid = sensitivity_table(table, mapper, x, y, metric, terrain=terrain, fixed=fixed)
        _heatmap(ax, grid, metric)
    where = f" on {terrain}" if terrain else ""
    fixed_text = ", ".join(f"{k}={v}" for k, v in (fixed or {}).items())
    fig.suptitle(f"{mapper}{where}" + (f" ({fixed_text})" if fixed_text else ""))
    return Plot(fig, Caption(f"{mapper_title(mapper)}: {x} x {y}",
                             f"Each metric over the {x} x {y} grid."))


def _effects_panels(table: pd.DataFrame, metrics: Sequence[str],
                    mappers: Sequence[str] | None) -> list[tuple[str, str]]:
    names = list(dict.fromkeys(table["mapper"])) if mappers is None else list(mappers)
    return [(name, column[2:]) for name in names
            for column in param_columns(mapper_rows(table, name))]


def effects_figure(table: pd.DataFrame, metrics: Sequence[str], *,
                   mappers: Sequence[str] | None = None) -> Plot:
    """Main effects: each metric's mean at each level of each swept parameter.

    One column per (mapper, parameter), one row per metric; the columns of one mapper
    share their y axis, so a flat curve beside a steep one reads as insensitive.
    """
    import matplotlib.pyplot as plt

    panels = _effects_panels(table, metrics, mappers)
    if not panels:
        raise ParameterError("sweep table: no mapper sweeps more than one parameter value")
    fig, axes = plt.subplots(len(metrics), len(panels), squeeze=False, layout="constrained",
                             figsize=(3.2 * len(panels), 2.5 * len(metrics)))
    for i, metric in enumerate(metrics):
        effects = {name: main_effects(table, name, metric) for name in dict(panels)}
        first: dict[str, Axes] = {}
        for ax, (name, param) in zip(axes[i], panels, strict=True):
            if name in first:
                ax.sharey(first[name])
            first.setdefault(name, ax)
            part = effects[name][effects[name]["param"] == param]
            ax.plot(range(len(part)), part["mean"].to_numpy(float), "o-")
            ax.set_xticks(range(len(part)), [_label(v) for v in part["level"]])
            ax.set(xlabel=f"{name}: {param}", ylabel=LABELS.get(metric, metric))
            ax.grid(alpha=0.3)
    fig.suptitle("main effects (mean over the other swept parameters)")
    return Plot(fig, MAIN_EFFECTS)
