"""Trade-off figures: one log-size panel per terrain, fronts with bands, equal-size reads."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
import pytest
from support.tradeoff import Curve, synthetic_tradeoff

from alte.errors import ParameterError
from alte.lab.plot.figure import read_caption
from alte.lab.studies.tradeoff.figures import (
    COLORS,
    CURVES,
    EQUAL_FIDELITY,
    EQUAL_SIZE,
    equal_fidelity_figure,
    equal_size_figure,
    save_tradeoff_figures,
    tradeoff_figure,
)


@pytest.fixture(scope="module")
def table():
    return synthetic_tradeoff({"alte2d": Curve(scale=0.5), "alte3d": Curve(scale=0.5)})


def _visible(fig):
    return [ax for ax in fig.axes if ax.get_visible()]





def test_tradeoff_figure_has_a_log_panel_per_terrain_and_a_front_per_mapper(table):
    fig = tradeoff_figure(table).figure
    axes = _visible(fig)
    assert [ax.get_title() for ax in axes] == ["sim_lan_1", "sim_lan_2", "sim_nav_1",
                                               "sim_nav_2"]
    assert all(ax.get_xscale() == ax.get_yscale() == "log" for ax in axes)  # errors: log-log
    assert axes[0].get_ylabel() == "MHD [m]" and axes[0].get_xlabel() == "basis functions"
    lan = axes[0]
    fronts = [line for line in lan.get_lines() if line.get_label().endswith(" front")]
    assert {line.get_label() for line in fronts} == {"Quadtree front", "2D-ALTE front"}
    quad = next(line for line in fronts if line.get_label() == "Quadtree front")
    alte = next(line for line in fronts if line.get_label() == "2D-ALTE front")
    # the winner's front lies below at a common size
    x = 3000.0
    assert np.interp(x, *alte.get_data()) < np.interp(x, *quad.get_data())
    assert len(lan.collections) >= 2 * 2 + 2  # dots (on / off the front) and bands
    stars = [line for line in lan.get_lines() if line.get_marker() == "*"]
    assert len(stars) == 2 and quad.get_color() == COLORS["quadtree"]
    assert "mean over 3 seeds" in fig.get_suptitle()
    plt.close(fig)


def test_tradeoff_figure_selects_and_reports_empty_selections(table):
    fig = tradeoff_figure(table, "completeness", mappers=["octomap"], terrains=["sim_nav_1"],
                          higher_is_better=True).figure
    (ax,) = _visible(fig)
    assert ax.get_title() == "sim_nav_1" and ax.get_ylabel() == "completeness"
    assert ax.get_yscale() == "linear"  # a share, not an error spanning decades
    plt.close(fig)
    with pytest.raises(ParameterError, match="no rows of"):
        tradeoff_figure(table, mappers=["octomap"], terrains=["sim_lan_1"])


def test_equal_size_figure_places_each_mapper_at_each_level(table):
    fig = equal_size_figure(table, ("quadtree", "alte2d"), levels=(1000, 5000, 20000)).figure
    axes = _visible(fig)
    assert len(axes) == 2 and axes[0].get_xlabel() == "basis functions"
    labels = [t.get_text() for t in axes[0].get_xticklabels()]
    assert labels == ["1,000", "5,000", "20,000"]
    plt.close(fig)


def test_equal_fidelity_figure_uses_a_log_size_axis(table):
    fig = equal_fidelity_figure(table, ("octomap", "alte3d")).figure
    axes = _visible(fig)
    assert all(ax.get_yscale() == "log" for ax in axes)
    assert axes[0].get_xlabel() == "MHD [m]"
    plt.close(fig)
    with pytest.raises(ParameterError, match="no terrain has every mapper"):
        equal_fidelity_figure(table, ("octomap", "quadtree"))


@pytest.mark.slow
def test_save_tradeoff_figures_writes_every_captioned_figure(tmp_path):
    """Every figure drawn, saved and captioned; Octomap (no height RMSE) alone on its
    terrain, whose panel a metric it lacks would leave empty. One seed: drawing is the
    cost, and the bands are another test's."""
    small = synthetic_tradeoff({"alte2d": Curve(scale=0.5)}, seeds=(0,), terrains={
        m: ("sim_lan_1",) for m in ("quadtree", "alte2d")} | {"octomap": ("sim_nav_1",)})
    out = save_tradeoff_figures(small.query("mapper != 'alte3d'"), tmp_path)
    drawn = {k for k, v in out.items() if not isinstance(v, str)}
    assert drawn == {"tradeoff_mhd", "tradeoff_accuracy", "tradeoff_completeness",
                     "tradeoff_height_rmse", "tradeoff_time", "tradeoff_memory",
                     "tradeoff_obstacle_recall", "tradeoff_obstacle_precision",
                     "equal_size_2d", "equal_fidelity_2d"}
    assert out["equal_size_3d"].startswith("not drawn: no terrain has every mapper")
    assert all((tmp_path / "figures" / f"{k}.png").stat().st_size > 1000 for k in drawn)
    captions = {**{k: c.caption for k, c in CURVES.items()},
                **{f"equal_size_{k}": c for k, c in EQUAL_SIZE.items()},
                **{f"equal_fidelity_{k}": c for k, c in EQUAL_FIDELITY.items()}}
    assert set(out) <= set(captions)
    assert {k: read_caption(tmp_path / "figures" / f"{k}.png").caption
            for k in drawn} == {k: captions[k] for k in drawn}


def test_a_further_mapper_gets_its_own_colour() -> None:
    """A plugin is never drawn in one of the thesis' four's colours (it was Quadtree's blue)."""
    from alte.lab.studies.tradeoff.figures import COLORS, mapper_color

    assert [mapper_color(m) for m in COLORS] == list(COLORS.values())
    others = [mapper_color(name) for name in ("elevation", "topgrid", "voxblox", "ufomap")]
    assert not set(others) & set(COLORS.values())
    assert mapper_color("elevation") == mapper_color("elevation")
