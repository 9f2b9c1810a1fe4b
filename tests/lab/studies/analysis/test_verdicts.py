"""The verdict rule, stated as intended behaviour: a clear win holds, a clear loss does not.

For every comparison kind (the thesis' point, the thesis' rule on our sweep, equal size,
equal fidelity) and every metric direction (lower is better, higher is better, ratios of
sizes and times), a synthetic table where one mapper clearly beats the other must give
"holds" for the claim that it wins and "does not hold" for the claim that the loser wins.
The per-seed statistic is oriented so that a positive value supports the claim, whatever
the metric's direction; the per-cell rule is checked at its boundaries on intervals whose
bounds are known exactly (identical seeds give a zero-width interval).
"""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pandas as pd
import pytest
from support.tradeoff import Curve, sweep_rows, synthetic_tradeoff

from alte.lab.studies.analysis.checks import NoDataError
from alte.lab.studies.analysis.comparisons import measure_compare
from alte.lab.studies.analysis.evidence import EvidenceSettings, evaluate, evaluate_all
from alte.lab.studies.analysis.measures import measure_check
from alte.lab.studies.analysis.tradeoff import prepare
from alte.lab.studies.thesis.claims import (
    Agreement,
    AllOf,
    Claim,
    Compare,
    Effect,
    NotMeasurable,
    Optimum,
    Summary,
    Trend,
)

#: 2D-ALTE's MHD curve lies at a fifth of Quadtree's: it wins every fidelity metric at
#: every size, and needs fewer basis functions, less memory and less time for any MHD.
WIN = {"alte2d": Curve(scale=0.2, seconds=0.002)}
KINDS = ("thesis_point", "rule", "equal_size", "equal_fidelity")
#: (metric, higher is better) per kind: fidelity metrics are read at equal size, sizes
#: and times at equal fidelity; the thesis' point and rule compare any column.
FIDELITY = (("mhd_m", False), ("accuracy_mean_m", False), ("height_rmse_m", False),
            ("completeness", True))
SIZES = (("basis_functions", False), ("memory_bytes", False), ("elapsed_s", False))
CASES = [(at, metric, hib) for at in KINDS for metric, hib in
         (FIDELITY if at == "equal_size" else SIZES if at == "equal_fidelity"
          else FIDELITY + SIZES)]


def _claim(check, claim_id: str = "test") -> Claim:
    return Claim(claim_id, "6", "a quote", check)


def _verdict(check, table: pd.DataFrame, **options) -> str:
    return evaluate(_claim(check), table, EvidenceSettings(**options)).verdict


@pytest.fixture(scope="module")
def win() -> pd.DataFrame:
    return synthetic_tradeoff(WIN)


@pytest.mark.parametrize(("at", "metric", "higher"), CASES)
def test_a_clear_win_holds_and_the_same_claim_for_the_loser_does_not(win, at, metric, higher):
    ours = Compare("lan", "alte2d", "quadtree", metric, at, higher_is_better=higher)
    theirs = Compare("lan", "quadtree", "alte2d", metric, at, higher_is_better=higher)
    found = evaluate(_claim(ours), win)
    assert (found.verdict, found.depends_on) == ("holds", "")
    assert (found.cells["outcome"] == "holds").all()
    ratio = metric in ("basis_functions", "memory_bytes", "elapsed_s")
    # the shown estimate supports the claim: a factor above 1, or a positive difference
    assert (found.cells["estimate"] > (1.0 if ratio else 0.0)).all()
    assert (found.cells["low"] <= found.cells["estimate"]).all()
    assert (found.cells["estimate"] <= found.cells["high"]).all()
    lost = evaluate(_claim(theirs), win)
    assert (lost.verdict, lost.depends_on) == ("does not hold", "")
    assert (lost.cells["high"] < (1.0 if ratio else 0.0)).all()


@pytest.mark.parametrize("at", ["equal_size", "thesis_point", "rule"])
def test_the_direction_of_the_metric_decides_the_winner(win, at):
    """Completeness is higher-is-better: the same numbers read as lower-is-better invert
    the verdict (the mutant that ignores ``higher_is_better`` flips this claim)."""
    right = Compare("lan", "alte2d", "quadtree", "completeness", at, higher_is_better=True)
    wrong = Compare("lan", "alte2d", "quadtree", "completeness", at, higher_is_better=False)
    assert _verdict(right, win) == "holds"
    assert _verdict(wrong, win) == "does not hold"


def test_the_difference_is_oriented_and_named_by_the_direction(win):
    lower = evaluate(_claim(Compare("lan", "alte2d", "quadtree", "mhd_m", "equal_size")), win)
    higher = evaluate(_claim(Compare("lan", "alte2d", "quadtree", "completeness", "equal_size",
                                     higher_is_better=True)), win)
    assert "MHD [m], Quadtree minus 2D-ALTE at equal basis functions" in lower.evidence
    assert "completeness, 2D-ALTE minus Quadtree at equal basis functions" in higher.evidence
    # completeness = 1 - MHD / 5 in the synthetic table: the two differences agree
    ratio = higher.cells["estimate"].to_numpy() / lower.cells["estimate"].to_numpy()
    np.testing.assert_allclose(ratio, 0.2, rtol=1e-9)
    size = evaluate(_claim(Compare("lan", "alte2d", "quadtree", "basis_functions",
                                   "equal_fidelity")), win)
    assert "basis functions, Quadtree / 2D-ALTE for equal MHD [m]" in size.evidence
    assert size.cells["unit"].eq("x").all() and lower.cells["unit"].eq("m").all()


def test_a_point_read_needs_no_size_or_fidelity_column(win):
    """Only equal-size reads need the size column, only equal-fidelity ones the fidelity
    column: a table without either still judges a comparison at the thesis' settings."""
    bare = win.assign(occupied_cells=np.nan, mhd_m=np.nan)
    check = Compare("lan", "alte2d", "quadtree", "memory_bytes", "thesis_point",
                    size="occupied_cells")
    assert _verdict(check, bare) == "holds"
    with pytest.raises(NoDataError, match="occupied_cells"):
        measure_compare(replace(check, at="equal_size"), bare)
    with pytest.raises(NoDataError, match=r"column\(s\) mhd_m"):
        measure_compare(replace(check, at="equal_fidelity"), bare)


def test_how_each_comparison_is_to_be_read(win):
    """What a comparison hands the verdict rule: ratio or difference, its unit, the
    claimed factor (ratios only), the band, the kind of level, and whether a time (or the
    rule's time-dependent pick) decides which values are read."""
    ready = prepare(win)

    def read(metric, at, **kw):
        m = measure_check(Compare("lan", "alte2d", "quadtree", metric, at, **kw), ready)
        return (m.ratio, m.unit, round(m.threshold, 9), round(m.band, 9), m.level_kind,
                m.time, m.read_from_times)

    log2, log15 = round(float(np.log(2.0)), 9), round(float(np.log1p(0.5)), 9)
    assert read("mhd_m", "thesis_point", factor=2.0, tolerance=0.5) == (
        False, "m", 0.0, 0.5, "", "", False)
    assert read("mhd_m", "rule", tolerance=0.1) == (False, "m", 0.0, 0.1, "", "", True)
    assert read("mhd_m", "equal_size", tolerance=0.1) == (False, "m", 0.0, 0.1, "size", "",
                                                          False)
    assert read("basis_functions", "equal_fidelity", factor=2.0, tolerance=0.5) == (
        True, "x", log2, log15, "fidelity", "", False)
    assert read("elapsed_s", "thesis_point", tolerance=0.1) == (
        True, "x", 0.0, round(float(np.log1p(0.1)), 9), "", "cpu", True)


def test_each_view_states_where_it_reads(win):
    texts = {at: evaluate(_claim(Compare("lan", "alte2d", "quadtree", "mhd_m", at)), win).evidence
             for at in ("thesis_point", "rule", "equal_size")}
    assert "at the thesis' chosen settings" in texts["thesis_point"]
    assert "at the settings the thesis' rule picks from our sweep" in texts["rule"]
    assert "at equal basis functions" in texts["equal_size"]


def _thesis_point_ratio(table: pd.DataFrame) -> float:
    """Quadtree's / 2D-ALTE's basis functions at the thesis' settings (tables 5.10: max
    points 150; kappa 0.05, max res 4, min pts 100), from the table."""
    qt = table.query("mapper == 'quadtree'")
    a2 = table.query("mapper == 'alte2d'")
    qt_n = qt[qt["params"] == json.dumps({"max_points": 150})]["basis_functions"].mean()
    a2_n = a2[a2["params"] == json.dumps({"kappa": 0.05, "max_res": 4, "min_pts": 100},
                                         sort_keys=True)]["basis_functions"].mean()
    return float(qt_n / a2_n)


def test_a_claimed_factor_is_the_threshold_of_a_ratio(win):
    """"Twenty times fewer basis functions" holds only where the ratio's interval lies
    above 20; the factor is read from the table, not assumed."""
    factor = _thesis_point_ratio(win)
    assert 30 < factor < 80  # the table's thesis settings: ~6,700 vs ~130 basis functions
    check = Compare("lan", "alte2d", "quadtree", "basis_functions", "thesis_point",
                    factor=factor / 1.5)
    assert _verdict(check, win) == "holds"
    found = evaluate(_claim(check), win)
    assert found.cells["estimate"].to_numpy() == pytest.approx([factor] * 2, rel=1e-6)
    assert f"above x{factor / 1.5:.3g}" in found.evidence
    bigger = Compare("lan", "alte2d", "quadtree", "basis_functions", "thesis_point",
                     factor=factor * 1.5)
    assert _verdict(bigger, win) == "does not hold"


def test_almost_the_same_is_a_band_around_one():
    """"Almost the same" holds where the ratio's interval lies within 1 +/- tolerance."""
    # Without noise, the basis functions 2D-ALTE needs for an MHD are about (scale ratio)
    # ** (1 / slope) times Quadtree's: x1.07 for a 2 % higher curve, x1.84 for 20 % (read
    # off fronts interpolated between the grid's maps, so not exactly).
    def curves(scale: float) -> pd.DataFrame:
        return synthetic_tradeoff({"alte2d": Curve(scale=scale, noise=0.0),
                                   "quadtree": Curve(noise=0.0)})

    check = Compare("lan", "alte2d", "quadtree", "basis_functions", "equal_fidelity",
                    relation="similar")
    for scale, expected in ((1.0, "holds"), (1.02, "holds"), (0.98, "holds"),
                            (1.2, "does not hold"), (0.8, "does not hold")):
        assert _verdict(check, curves(scale)) == expected, scale
    found = evaluate(_claim(check), curves(1.02))
    assert found.cells["estimate"].between(1 / 1.25, 1.25).all()
    narrow = Compare("lan", "alte2d", "quadtree", "basis_functions", "equal_fidelity",
                     relation="similar", tolerance=0.05)
    assert _verdict(narrow, curves(1.02)) == "does not hold"
    # the shown factor is the first named mapper's over the second's, whichever is larger
    apart = evaluate(_claim(check), curves(1.2))
    assert "basis functions, 2D-ALTE / Quadtree" in apart.evidence
    assert (apart.cells["estimate"] > 1.5).all()
    # a tolerance of 1.0 on a ratio is "within a factor 2" (not e): x1.6 holds, x2.4 not
    wide = Compare("lan", "alte2d", "quadtree", "basis_functions", "equal_fidelity",
                   relation="similar", tolerance=1.0)
    assert _verdict(wide, curves(1.15)) == "holds"
    assert _verdict(wide, curves(1.3)) == "does not hold"
    assert (evaluate(_claim(wide), curves(1.3)).cells["estimate"].between(2.1, 2.6)).all()


def test_times_known_within_their_spread_cannot_be_shown_equal():
    """Equal CPU times, each known only within its spread (at least the floor), give an
    interval wider than the 25 % band: the similarity of times stays uncertain."""
    equal = 6667 / 127.4 * 0.01  # seconds per 1000 cells that equal the thesis maps' times
    check = Compare("lan", "alte2d", "quadtree", "elapsed_s", "thesis_point", relation="similar")
    found = evaluate(_claim(check), synthetic_tradeoff({"alte2d": Curve(seconds=equal)}))
    assert (found.verdict, found.depends_on) == ("depends", "uncertainty")
    np.testing.assert_allclose(found.cells["estimate"], 1.0, atol=0.01)
    assert (found.cells["low"] < 1 / 1.25).all() and (found.cells["high"] > 1.25).all()
    far = evaluate(_claim(check), synthetic_tradeoff({"alte2d": Curve(seconds=equal * 4)}))
    assert far.verdict == "does not hold"


# ---------------------------------------------------------------- other kinds of check


_sweep = sweep_rows


@pytest.mark.parametrize("sign", [+1, -1])
def test_a_trend_holds_in_its_stated_direction_only(sign):
    rising = _sweep("quadtree", [10, 20, 30, 40, 50], {"mhd_m": [1.0, 1.1, 1.3, 1.2, 1.6]},
                    param="max_points")
    check = Trend("lan", "quadtree", "max_points", "mhd_m", sign)
    found = evaluate(_claim(check), rising)
    # Spearman rho of (1, 1.1, 1.3, 1.2, 1.6) with the levels: 1 - 6 * 2 / (5 * 24) = 0.9
    assert found.cells["estimate"].to_numpy() == pytest.approx([0.9 * sign])
    assert found.verdict == ("holds" if sign > 0 else "does not hold")
    weak = Trend("lan", "quadtree", "max_points", "mhd_m", sign, min_rho=0.95)
    assert _verdict(weak, rising) == "does not hold"


def test_a_trend_over_the_larger_maps_ignores_the_small_ones():
    # MHD falls over the small maps and rises over the larger half (by basis functions)
    table = _sweep("alte2d", [1, 2, 3, 4, 5, 6], {"mhd_m": [4.0, 3.0, 2.0, 1.0, 1.5, 2.5]})
    whole = Trend("lan", "alte2d", "x", "mhd_m", +1)
    larger = Trend("lan", "alte2d", "x", "mhd_m", +1, largest_half=True)
    assert _verdict(whole, table) == "does not hold"
    assert _verdict(larger, table) == "holds"


@pytest.mark.parametrize(("finest", "expected"), [("low", "holds"), ("high", "does not hold")])
def test_an_interior_optimum_beats_the_finest_setting(finest, expected):
    # best (lowest) MHD at x = 20; the low end is worse, the high end better still
    table = _sweep("quadtree", [10, 20, 30, 40], {"mhd_m": [1.5, 1.0, 1.2, 0.8]},
                   param="max_points")
    found = evaluate(_claim(Optimum("lan", "quadtree", "max_points", "mhd_m", finest)), table)
    assert found.cells["estimate"].to_numpy() == pytest.approx(
        [0.5 if finest == "low" else -0.2])
    assert found.verdict == expected


def _two_params(spread_a: float, spread_b: float) -> pd.DataFrame:
    """2D-ALTE over a full a x b grid: the metric moves by ``spread_*`` per level."""
    rows = [{"terrain": "sim_lan_1", "mapper": "alte2d", "seed": s, "p_max_res": a,
             "p_kappa": b, "params": f"max_res={a}, kappa={b}",
             "basis_functions": 100.0 * (1 + spread_a * a + spread_b * b) * (1 + 0.01 * s),
             "occupied_cells": 10, "memory_bytes": 1, "elapsed_s": 1.0, "mhd_m": 1.0,
             "hd_m": 2.0, "accuracy_mean_m": 0.1, "completeness": 0.9}
            for s in (0, 1, 2) for a in (0, 1, 2) for b in (0, 1, 2)]
    return pd.DataFrame(rows)


def test_an_effect_compares_the_two_parameters_in_the_stated_order():
    table = _two_params(1.0, 0.1)
    check = Effect("lan", "alte2d", "basis_functions", "max_res", other="kappa")
    found = evaluate(_claim(check), table)
    # at fixed kappa the range over max_res is 200 (x the seed factor), over kappa 20; the
    # mean is 100 * (1 + 1 + 0.1) = 210 (x the same factor): (200 - 20) / 210
    assert found.cells["estimate"].to_numpy() == pytest.approx([180 / 210])
    assert found.verdict == "holds"
    swapped = Effect("lan", "alte2d", "basis_functions", "kappa", other="max_res")
    assert _verdict(swapped, table) == "does not hold"


def test_no_considerable_effect_is_a_spread_under_the_limit():
    table = _two_params(1.0, 0.01)
    small = Effect("lan", "alte2d", "basis_functions", "kappa", max_spread=0.1)
    found = evaluate(_claim(small), table)
    assert found.cells["estimate"].to_numpy() == pytest.approx([0.1 - 2 / 201])
    assert found.verdict == "holds"
    large = Effect("lan", "alte2d", "basis_functions", "max_res", max_spread=0.1)
    assert _verdict(large, table) == "does not hold"


def test_agreement_with_the_truth_in_both_forms():
    # MHD follows the true RMSE exactly; HD is unrelated to it
    table = _sweep("quadtree", [1, 2, 3, 4, 5],
                   {"mhd_m": [1.0, 2.0, 3.0, 4.0, 5.0], "hd_m": [5.0, 3.0, 6.0, 4.0, 5.5],
                    "height_rmse_m": [0.1, 0.2, 0.3, 0.4, 0.6],
                    "completeness": [0.9, 0.8, 0.7, 0.6, 0.5]}, jitter=0.01)
    better = Agreement("lan", "quadtree", "mhd_m", "height_rmse_m", other="hd_m")
    worse = Agreement("lan", "quadtree", "hd_m", "height_rmse_m", other="mhd_m")
    assert _verdict(better, table) == "holds"
    assert _verdict(worse, table) == "does not hold"
    # "not sensitive": MHD tracks the loss of completeness perfectly, so the claim fails;
    # with the wrong sign (completeness read as lower-is-better) it would hold
    insensitive = Agreement("lan", "quadtree", "mhd_m", "completeness", sign=-1)
    found = evaluate(_claim(insensitive), table)
    assert found.cells["estimate"].to_numpy() == pytest.approx([0.5 - 1.0])
    assert found.verdict == "does not hold"
    assert _verdict(Agreement("lan", "quadtree", "mhd_m", "completeness"), table) == "holds"


def _summary_table() -> pd.DataFrame:
    a = _sweep("alte2d", [1, 2, 3], {"size_octaves": [4.0, 5.0, 6.0],
                                     "mhd_m": [1.0, 1.1, 1.2]}, jitter=0.01)
    b = _sweep("quadtree", [1, 2, 3], {"size_octaves": [1.0, 2.0, 3.0],
                                       "mhd_m": [1.0, 2.0, 3.0]}, jitter=0.01)
    return pd.concat([a, b], ignore_index=True)


@pytest.mark.parametrize("higher", [True, False])
def test_a_summary_respects_the_direction_of_its_column(higher):
    table = _summary_table()
    octaves = Summary("lan", "alte2d", "size_octaves", "median", "quadtree",
                      higher_is_better=higher)
    found = evaluate(_claim(octaves), table)
    assert found.cells["estimate"].to_numpy() == pytest.approx([3.0 if higher else -3.0],
                                                               rel=0.05)
    assert found.verdict == ("holds" if higher else "does not hold")
    first, second = ("2D-ALTE", "Quadtree") if higher else ("Quadtree", "2D-ALTE")
    assert (f"median of cell-size octaves over the settings, {first} minus {second}"
            in found.evidence)
    assert found.cells["unit"].eq("").all()  # octaves have no unit
    reverse = Summary("lan", "quadtree", "size_octaves", "median", "alte2d",
                      higher_is_better=higher)
    assert _verdict(reverse, table) == ("does not hold" if higher else "holds")


def test_a_summary_against_a_threshold_and_a_coefficient_of_variation():
    table = _summary_table()
    steady = Summary("lan", "alte2d", "mhd_m", "cv", "quadtree")  # lower cv is better
    found = evaluate(_claim(steady), table)
    cv = np.std([1.0, 2.0, 3.0]) / 2.0 - np.std([1.0, 1.1, 1.2]) / 1.1
    assert found.cells["estimate"].to_numpy() == pytest.approx([cv], rel=1e-9)
    assert found.verdict == "holds" and found.cells["unit"].eq("").all()  # a ratio: no unit
    assert _verdict(Summary("lan", "quadtree", "mhd_m", "cv", "alte2d"), table) == (
        "does not hold")
    median = evaluate(_claim(Summary("lan", "alte2d", "mhd_m", "median", "quadtree")), table)
    assert median.cells["unit"].eq("m").all() and median.verdict == "holds"
    assert "median of MHD [m] over the settings, Quadtree minus 2D-ALTE" in median.evidence
    above = Summary("lan", "alte2d", "size_octaves", "median", higher_is_better=True,
                    threshold=4.5)
    below = Summary("lan", "alte2d", "size_octaves", "median", higher_is_better=True,
                    threshold=5.5)
    # the median over 2D-ALTE's settings is 5 x (1 + 0.01 seed): 5.05 over seeds 0..2
    assert evaluate(_claim(above), table).cells["estimate"].to_numpy() == pytest.approx(
        [0.55], rel=1e-9)
    assert _verdict(above, table) == "holds" and _verdict(below, table) == "does not hold"
    assert "median of cell-size octaves over the settings, 2D-ALTE minus 4.5" in evaluate(
        _claim(above), table).evidence


# ---------------------------------------------------------------- the per-cell rule


def _flat(value: float, seeds: int = 3) -> pd.DataFrame:
    """A Trend whose per-seed rho is exactly ``value`` in every seed (zero-width interval):
    rho of three levels is 1, 0.5 or -0.5 ... ; min_rho shifts it onto the threshold."""
    rows = []
    for seed in range(seeds):
        for i, x in enumerate((1, 2, 3)):
            rows.append({"terrain": "sim_lan_1", "mapper": "quadtree", "seed": seed,
                         "params": json.dumps({"max_points": x}), "basis_functions": 10 + i,
                         "occupied_cells": 5, "memory_bytes": 1, "elapsed_s": 1.0,
                         "mhd_m": (1.0, 2.0, 3.0)[i] if value > 0 else (3.0, 2.0, 1.0)[i],
                         "hd_m": 5.0, "accuracy_mean_m": 0.1, "completeness": 0.9})
    return pd.DataFrame(rows)


@pytest.mark.parametrize(("min_rho", "expected"), [(0.99, "holds"), (1.0, "inconclusive"),
                                                  (1.01, "does not hold")])
def test_an_interval_touching_the_threshold_is_inconclusive(min_rho, expected):
    table = _flat(1.0)  # rho = 1 in every seed: the interval is [1, 1]
    found = evaluate(_claim(Trend("lan", "quadtree", "max_points", "mhd_m", +1,
                                  min_rho=min_rho)), table)
    assert found.cells["outcome"].tolist() == [expected]
    assert found.verdict == (expected if expected != "inconclusive" else "depends")
    assert found.depends_on == ("uncertainty" if expected == "inconclusive" else "")


def test_too_few_seeds_are_inconclusive_whatever_the_values():
    table = _flat(1.0, seeds=2)
    check = Trend("lan", "quadtree", "max_points", "mhd_m", +1)
    assert evaluate(_claim(check), table).cells["outcome"].tolist() == ["holds"]
    strict = evaluate(_claim(check), table, EvidenceSettings(min_seeds=3))
    assert strict.cells["outcome"].tolist() == ["inconclusive"]
    assert (strict.verdict, strict.depends_on) == ("depends", "uncertainty")


def test_undecided_and_similar_bounds_are_closed():
    """Neither better: holds when the interval contains 0, its ends included; similar:
    holds when the interval lies within the band, its ends included; an infinite end is
    an unbounded side (the other end still decides), a NaN end decides nothing."""
    from alte.lab.studies.analysis.evidence import _outcome
    from alte.lab.studies.analysis.measures import CheckValues

    empty = pd.DataFrame(columns=["terrain", "level", "seed", "value"])
    undecided = CheckValues(empty, "d", relation="undecided")
    similar = CheckValues(empty, "r", ratio=True, relation="similar", band=0.2)
    better = CheckValues(empty, "d", threshold=0.5)
    cases = [(undecided, 0.0, 0.0, "holds"), (undecided, 0.0, 1.0, "holds"),
             (undecided, -1.0, 0.0, "holds"), (undecided, 0.1, 1.0, "does not hold"),
             (undecided, -1.0, -0.1, "does not hold"),
             (similar, -0.2, 0.2, "holds"), (similar, 0.0, 0.2, "holds"),
             (similar, -0.2, 0.0, "holds"), (similar, 0.1, 0.3, "inconclusive"),
             (similar, -0.3, -0.1, "inconclusive"), (similar, 0.2, 0.3, "inconclusive"),
             (similar, -0.3, -0.2, "inconclusive"), (similar, 0.21, 0.3, "does not hold"),
             (similar, -0.3, -0.21, "does not hold"), (similar, -0.3, 0.3, "inconclusive"),
             (better, 0.5, 0.9, "inconclusive"), (better, 0.51, 0.9, "holds"),
             (better, 0.1, 0.5, "inconclusive"), (better, 0.1, 0.49, "does not hold"),
             (better, np.nan, 0.9, "inconclusive"), (better, 0.6, np.nan, "inconclusive"),
             (better, 0.6, np.inf, "holds"), (better, -np.inf, 0.4, "does not hold"),
             (better, -np.inf, 0.9, "inconclusive"), (better, -np.inf, np.inf, "inconclusive")]
    got = [_outcome(low, high, 3, m, 2) for m, low, high, _ in cases]
    assert got == [expected for *_, expected in cases]
    assert _outcome(0.6, 0.9, 1, better, 2) == "inconclusive"
    assert _outcome(0.6, 0.9, 2, better, 2) == "holds"


# ---------------------------------------------------------------- conjunctions


def test_a_conjunction_holds_only_when_every_part_does(win):
    holds = Compare("lan", "alte2d", "quadtree", "mhd_m", "equal_size")
    fails = Compare("lan", "quadtree", "alte2d", "mhd_m", "equal_size")
    fails_too = Compare("lan", "quadtree", "alte2d", "completeness", "equal_size",
                        higher_is_better=True)
    unmeasurable = NotMeasurable("a judgement")
    all_hold = evaluate(_claim(AllOf((holds, holds))), win)
    assert (all_hold.verdict, all_hold.depends_on) == ("holds", "")
    all_fail = evaluate(_claim(AllOf((fails, fails_too))), win)
    assert (all_fail.verdict, all_fail.depends_on) == ("does not hold", "")
    both = evaluate(_claim(AllOf((holds, fails))), win)
    assert (both.verdict, both.depends_on) == ("depends", "mapper")
    metric = evaluate(_claim(AllOf((holds, fails_too))), win)
    assert (metric.verdict, metric.depends_on) == ("depends", "metric")
    partly = evaluate(_claim(AllOf((holds, unmeasurable))), win)
    assert (partly.verdict, partly.depends_on) == ("depends", "untested part")
    none = evaluate(_claim(AllOf((unmeasurable, unmeasurable))), win)
    assert (none.verdict, none.depends_on) == ("not measurable", "")
    lacking = evaluate(_claim(AllOf((Compare("nav", "alte3d", "octomap", "mhd_m",
                                             "equal_size"), unmeasurable))),
                       win.query("mapper != 'octomap'"))
    assert (lacking.verdict, lacking.depends_on) == ("no data", "")
    assert "(1) not measured: no rows of octomap" in lacking.evidence
    assert "(2) a judgement -> not measurable." in lacking.evidence


def test_shared_checks_are_measured_once_and_give_the_same_answer(win):
    check = Compare("lan", "alte2d", "quadtree", "mhd_m", "equal_size")
    findings = evaluate_all([_claim(check, "a"), _claim(AllOf((check, check)), "b")], win)
    assert [f.verdict for f in findings] == ["holds", "holds"]
    assert [f.claim.id for f in findings] == ["a", "b"]
    single = findings[0].cells
    assert set(single["id"]) == {"a"} and set(findings[1].cells["part"]) == {1, 2}
    np.testing.assert_array_equal(single["estimate"],
                                  findings[1].cells.query("part == 1")["estimate"])


def test_a_size_option_replaces_basis_functions_in_every_part(win):
    check = AllOf((Compare("lan", "alte2d", "quadtree", "basis_functions", "equal_fidelity"),
                   Compare("lan", "alte2d", "quadtree", "mhd_m", "equal_size")))
    plain = evaluate(_claim(check), win)
    occupied = evaluate(_claim(check), win, EvidenceSettings(size="occupied_cells"))
    assert "basis functions, Quadtree / 2D-ALTE" in plain.evidence
    assert "occupied cells, Quadtree / 2D-ALTE" in occupied.evidence
    assert "at equal occupied cells" in occupied.evidence
    assert "basis functions" not in occupied.evidence


def test_a_read_without_its_axis_or_a_shared_range_is_no_data(win):
    """Equal-size reads need the size column, equal-fidelity reads the fidelity column,
    and both mappers on a common terrain; otherwise the claim gets "no data", saying why."""
    blank = win.assign(cost=np.nan)
    at_size = Compare("lan", "alte2d", "quadtree", "mhd_m", "equal_size", size="cost")
    found = evaluate(_claim(at_size), blank)
    assert found.verdict == "no data" and "no values in column(s) cost" in found.evidence
    at_fidelity = Compare("lan", "alte2d", "quadtree", "basis_functions", "equal_fidelity",
                          fidelity="cost")
    found = evaluate(_claim(at_fidelity), blank)
    assert found.verdict == "no data" and "no values in column(s) cost" in found.evidence
    apart = synthetic_tradeoff(WIN, terrains={"alte2d": ("sim_lan_1",),
                                              "quadtree": ("sim_lan_2",)})
    found = evaluate(_claim(Compare("lan", "alte2d", "quadtree", "mhd_m", "equal_size")), apart)
    assert found.verdict == "no data"
    assert "2D-ALTE and Quadtree share no terrain and size range" in found.evidence
