"""Cross-validation of the pose defaults: choose on one sequence, score on the other, and
the real-data pose figure."""

from __future__ import annotations

import pandas as pd

from alte.lab.studies.poses.benchmark import COLUMNS
from alte.lab.studies.poses.defaults import Candidate, choices
from alte.lab.studies.realdata import figures as realdata_plot

WINDOW = Candidate("kiss", "window", (0, 10, 20), 20)
GAIN = Candidate("refine", "min_gain", (0.1, 0.2, 0.3), 0.3, "loose")


def _runs(setting: str, scores: dict[str, dict[object, tuple[float, float]]]) -> pd.DataFrame:
    """Rows of :func:`cross_validation`: per sequence and value, (cloud median m, CPU ms)."""
    return pd.DataFrame([{"sequence": seq, "setting": setting, "value": value,
                          "cloud_median_m": median, "cpu_ms_per_scan": cpu}
                         for seq, values in scores.items()
                         for value, (median, cpu) in values.items()])


def test_a_value_that_wins_on_both_holds_and_ties_go_to_the_cheapest() -> None:
    runs = _runs("kiss:window", {
        "a": {0: (0.030, 60.0), 10: (0.0200, 70.0), 20: (0.0201, 80.0)},
        "b": {0: (0.040, 60.0), 10: (0.0202, 70.0), 20: (0.0200, 80.0)}})
    table = choices(runs, [WINDOW]).set_index("chosen_on")
    assert table.loc["a", "chosen"] == 10 and table.loc["b", "chosen"] == 10  # b: a 1 % tie
    assert bool(table["holds"].all())
    assert table.loc["a", "regret"] == 0.0202 / 0.0200 - 1
    assert table.loc["a", "safe"] == 20  # the lowest worst score: 0.0201 against 0.0202


def test_a_value_that_wins_on_one_and_loses_on_the_other_does_not_hold() -> None:
    """The loosest refinement threshold that keeps sequence a as recorded corrects scans
    of b: chosen on a, it does not hold on b; the safe value is the stricter one."""
    runs = _runs("refine:min_gain", {
        "a": {0.1: (0.0046, 0.0), 0.2: (0.0046, 0.0), 0.3: (0.0046, 0.0)},
        "b": {0.1: (0.0068, 0.0), 0.2: (0.0064, 0.0), 0.3: (0.0064, 0.0)}})
    table = choices(runs, [GAIN]).set_index("chosen_on")
    assert table.loc["a", "chosen"] == 0.1 and not table.loc["a", "holds"]
    assert table.loc["b", "chosen"] == 0.2 and table.loc["b", "holds"]
    assert table.loc["a", "safe"] == 0.2 and table.loc["a", "default_regret"] == 0.0


def test_settings_without_runs_are_left_out() -> None:
    runs = _runs("kiss:voxel", {"a": {1.5: (0.02, 80.0)}, "b": {1.5: (0.02, 80.0)}})
    assert choices(runs, [WINDOW]).empty


def test_pose_figure_draws_every_source_on_every_sequence() -> None:
    assert realdata_plot.poses_figure(pd.DataFrame(columns=list(COLUMNS))) is None
    rows = [{"input": seq, "source": source, "cloud_median_m": median, "ate_m": ate,
             "cpu_ms_per_scan": cpu}
            for seq in ("balm_seq", "balm_seq2")
            for source, median, ate, cpu in (("recorded", 0.0046, 0.0, 0.0),
                                             ("kiss", 0.019, 0.021, 80.0),
                                             ("refine", 0.0046, 0.0, 120.0))]
    plot = realdata_plot.poses_figure(pd.DataFrame(rows))
    assert plot is not None and len(plot.figure.axes) == len(realdata_plot.POSE_PANELS)
    bars = plot.figure.axes[0].patches
    assert len(bars) == 6 and min(b.get_height() for b in bars) > 0  # log axes: no zero
