"""alte.lab.studies.tradeoff.ablation: a pair's trade-off curves with one thing changed."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import pandas as pd
import pytest
from support.tradeoff import Curve, synthetic_tradeoff

from alte.errors import ParameterError
from alte.lab.plot.figure import read_caption
from alte.lab.studies.tradeoff.ablation import ABLATIONS, ablation_figure, save_ablation_figures


def _visible(fig):
    return [ax for ax in fig.axes if ax.get_visible()]


def test_ablation_figure(tmp_path):
    where = {m: ("sim_lan_2",) for m in ("quadtree", "alte2d")} | {
        m: ("sim_nav_1",) for m in ("octomap", "alte3d")}
    base = synthetic_tradeoff(seeds=(0, 1), terrains=where).assign(variant="base")
    other = synthetic_tradeoff({"alte2d": Curve(scale=0.3)}, seeds=(0, 1),
                               terrains=where).assign(variant="centres")
    variants = pd.concat([base, other], ignore_index=True)
    fig = ablation_figure(variants, ("quadtree", "alte2d"), "sim_lan_2").figure
    titles = [ax.get_title() for ax in _visible(fig)]
    assert titles == ["base", "centres", "base, size = occupied cells"]
    same = pd.concat([variants, base.assign(variant="no change")], ignore_index=True)
    titles = [ax.get_title() for ax in _visible(ablation_figure(same, ("quadtree", "alte2d"),
                                                                "sim_lan_2").figure)]
    assert "no change" not in titles  # a variant that changed nothing here gets no panel
    assert _visible(fig)[2].get_xlabel() == "occupied cells"
    plt.close(fig)
    with pytest.raises(ParameterError, match=r"no ablation variants of \['quadtree', 'alte2d'\] "
                       "on sim_nav_1"):
        ablation_figure(variants, ("quadtree", "alte2d"), "sim_nav_1")
    with pytest.raises(ParameterError, match="no ablation variants"):
        ablation_figure(base, ("octomap", "alte3d"), "sim_nav_1")
    out = save_ablation_figures(variants, tmp_path)
    assert set(out) == {"tradeoff_ablation_2d", "tradeoff_ablation_3d"}
    assert (tmp_path / "figures" / "tradeoff_ablation_2d.png").stat().st_size > 1000
    saved = read_caption(tmp_path / "figures" / "tradeoff_ablation_2d.png")
    assert saved is not None and saved.caption == ABLATIONS["2d"]
    assert str(out["tradeoff_ablation_3d"]).startswith("not drawn")  # 3D maps unchanged
    lone = save_ablation_figures(base, tmp_path / "lone")
    assert all(str(v).startswith("not drawn: no ablation variants") for v in lone.values())
