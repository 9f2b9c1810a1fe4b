"""Tests for the terrain-map figures."""

from __future__ import annotations

import matplotlib as mpl
import numpy as np

mpl.use("Agg")

from alte.lab.plot.terrain import map_grid_figure
from alte.mappers import make_mapper
from alte.mappers.domain import Domain


def test_map_grid_figure_draws_one_panel_per_map() -> None:
    rng = np.random.default_rng(0)
    xy = rng.uniform(0, 16, (4000, 2))
    cloud = np.column_stack([xy, np.where(np.all((xy > 6) & (xy < 10), axis=1), 2.0, 0.0)])
    maps = []
    for max_res in (2, 4):
        mapper = make_mapper("alte2d", {"max_res": max_res}, domain=Domain(0, 0, -1, 16))
        mapper.build(cloud)
        maps.append(mapper)
    fig = map_grid_figure(maps, ["a", "b"], columns=3).figure
    visible = [ax for ax in fig.axes if ax.get_visible() and ax.get_title()]
    assert [ax.get_title() for ax in visible] == ["a", "b"]
