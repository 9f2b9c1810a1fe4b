"""Sweep figures: one heatmap per metric, main-effect panels per mapper parameter."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import pytest

from alte.errors import ParameterError
from alte.lab.studies.sweep.figures import effects_figure, sensitivity_figure


def _table():
    rows = [{"mapper": "alte2d", "terrain": "t", "p_kappa": k, "p_max_res": r,
             "mhd_m": k + r, "basis_functions": 4**r}
            for k in (0.01, 0.1, 1.0) for r in (4, 5)]
    rows += [{"mapper": "quadtree", "terrain": "t", "p_max_points": m, "mhd_m": m / 100,
              "basis_functions": 1000 // m} for m in (25, 100)]
    return pd.DataFrame(rows)


def test_sensitivity_figure_draws_one_annotated_heatmap_per_metric():
    plot = sensitivity_figure(_table(), "alte2d", "kappa", "max_res",
                              ["mhd_m", "basis_functions"])
    assert plot.caption.title == "2D-ALTE: kappa x max_res"
    assert plot.caption.text == "Each metric over the kappa x max_res grid."
    fig = plot.figure
    heatmaps = [ax for ax in fig.axes if ax.images]
    assert len(heatmaps) == 2
    values = heatmaps[0].images[0].get_array()
    assert values.shape == (2, 3) and np.allclose(values[1], [5.01, 5.1, 6.0])
    assert [t.get_text() for t in heatmaps[0].get_xticklabels()] == ["0.01", "0.1", "1"]
    assert [t.get_text() for t in heatmaps[1].texts] == ["256"] * 3 + ["1024"] * 3
    plt.close(fig)


def test_effects_figure_has_a_panel_per_metric_and_parameter():
    fig = effects_figure(_table(), ["mhd_m", "basis_functions"]).figure
    assert [ax.get_xlabel() for ax in fig.axes[:3]] == ["alte2d: kappa", "alte2d: max_res",
                                                       "quadtree: max_points"]
    assert len(fig.axes) == 6
    # the two alte2d panels of a row share y, quadtree's does not
    assert fig.axes[0].get_ylim() == fig.axes[1].get_ylim() != fig.axes[2].get_ylim()
    plt.close(fig)


def test_sweep_figure_errors():
    with pytest.raises(ParameterError, match="no alte3d rows"):
        sensitivity_figure(_table(), "alte3d", "max_res", "min_pts", ["mhd_m"])
    single = _table().query("mapper == 'quadtree'").head(1)
    with pytest.raises(ParameterError, match="no mapper sweeps more than one"):
        effects_figure(single, ["mhd_m"])
