"""Captions on the front page: read from beside each figure, a notebook's own first."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import numpy as np
import pandas as pd

from alte.lab.plot.figure import Caption, Plot, SavedCaption
from alte.lab.plot.render import save_figure
from alte.lab.plot.scene import POSE_HISTORY, TRAJECTORY, plot_pose_history, plot_trajectory
from alte.lab.plot.terrain import cloud_figure
from alte.lab.report.captions import CHAPTERS, caption, chapter_title
from alte.lab.report.page import run_page
from alte.lab.report.plan import PLAN
from alte.lab.studies.sweep.figures import sensitivity_figure
from alte.lab.studies.tradeoff.figures import CURVES, EQUAL_SIZE
from alte.types import Trajectory

#: The front page's words for a sample of figures, as the page read before captions moved
#: beside the code that draws them (title, text after filling TERRAIN=sim_lan_1).
_FRONT = ("Each dot is one map (a parameter setting and seed); the line is the mapper's Pareto "
          "front (no other of its maps is both smaller and better) averaged over seeds, the "
          "band its 95 % bootstrap interval over seeds; the star marks the thesis' chosen "
          "setting. Size on a log axis, and errors and times too (they span decades over a "
          "grid); completeness on a linear one.")
PAGE_TEXT = {
    "cloud": ("Registered cloud", "The registered point cloud of sim_lan_1."),
    "trajectory": ("Trajectory", "The vehicle's path over sim_lan_1."),
    "pose_history": ("Position and attitude (fig. 4.2)", "Position and attitude against time."),
    "alte2d_kappa_max_res": ("2D-ALTE: kappa x max_res",
                             "Each metric over the kappa x max_res grid."),
    "tradeoff_time": ("Mapping time against map size",
                      "Time spent in the mapper calls only. " + _FRONT),
    "equal_size_3d": ("3D maps at equal size",
                      "MHD each 3D mapper reaches at the same number of basis functions, read "
                      "off its front; mean over seeds with 95 % bootstrap intervals."),
}


def _figures() -> dict[str, Plot]:
    """The sample, drawn by the functions the notebooks call (cheap inputs)."""
    rng = np.random.default_rng(0)
    path = np.cumsum(rng.normal(size=(20, 3)), axis=0)
    stamps = np.arange(20, dtype=np.int64) * 100_000_000
    quats = np.tile([0.0, 0.0, 0.0, 1.0], (20, 1))
    sweep = pd.DataFrame([{"mapper": "alte2d", "terrain": "t", "p_kappa": k, "p_max_res": r,
                           "mhd_m": k + r} for k in (0.1, 1.0) for r in (4, 5)])
    blank = Plot(cloud_figure(path).figure, Caption("unused", "unused"))
    return {
        "cloud": cloud_figure(path),
        "trajectory": plot_trajectory(path, caption=TRAJECTORY),
        "pose_history": plot_pose_history(Trajectory(stamps, path, quats, path)),
        "alte2d_kappa_max_res": sensitivity_figure(sweep, "alte2d", "kappa", "max_res",
                                                   ["mhd_m"]),
        "tradeoff_time": Plot(blank.figure, CURVES["tradeoff_time"].caption),
        "equal_size_3d": Plot(blank.figure, EQUAL_SIZE["3d"]),
    }


def test_the_page_reads_as_before_in_the_order_figures_were_saved(tmp_path: Path) -> None:
    plots = _figures()
    order = ["trajectory", "tradeoff_time", "pose_history", "cloud", "equal_size_3d",
             "alte2d_kappa_max_res"]
    for name in order:
        save_figure(plots[name], tmp_path / "ch4_sim_lan_1", name)
    record = {"mode": "quick", "started": "now", "seconds": 1.0, "problems": [],
              "runs": [{"name": "ch4_sim_lan_1", "status": "ok", "seconds": 1.0,
                        "parameters": {"TERRAIN": "sim_lan_1"}}]}
    page = run_page(record, tmp_path, [])
    shown = {Path(f.src).stem: (f.title, f.caption)
             for f in [*page.tradeoff, *page.sections[0].figures]}
    assert shown == PAGE_TEXT
    assert [Path(f.src).stem for f in page.tradeoff] == ["tradeoff_time", "equal_size_3d"]
    assert [Path(f.src).stem for f in page.sections[0].figures] == [
        "trajectory", "pose_history", "cloud", "alte2d_kappa_max_res"]  # as saved


def test_caption_precedence_and_fields() -> None:
    saved = SavedCaption(Caption("Registered cloud", "The registered point cloud of {TERRAIN}."),
                         0)
    params = {"TERRAIN": "sim_lan_1"}
    assert caption("cloud", saved, params).text == "The registered point cloud of sim_lan_1."
    own = caption("cloud", saved, params, {"cloud": "Mine."})
    assert (own.title, own.text) == ("Registered cloud", "Mine.")
    assert caption("cloud", saved, params, {"cloud": ""}).text.endswith("sim_lan_1.")
    unknown = caption("odd_one", None, params, {"other": "x"})
    assert (unknown.title, unknown.text) == ("odd one", "(no caption)")
    assert caption("odd_one", None, params, {"odd_one": "Its own."}).text == "Its own."
    assert caption("cloud", saved, {}).text == "The registered point cloud."
    assert POSE_HISTORY.text == "Position and attitude against time."


def test_every_planned_notebook_has_a_chapter_title() -> None:
    assert {Path(e.notebook).stem for e in PLAN} <= set(CHAPTERS)


def test_chapter_titles() -> None:
    assert chapter_title("ch4_terrain", "ch4_sim_nav_2", {"TERRAIN": "sim_nav_2"}) == (
        "Chapter 4: terrain sim_nav_2")
    assert chapter_title("ch2_test_benchmark", "ch2", {}) == (
        "Chapter 2: the test benchmark")
    assert chapter_title("custom", "my_run", {}) == "my run"
