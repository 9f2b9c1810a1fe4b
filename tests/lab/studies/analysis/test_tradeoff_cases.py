"""Trade-off fronts and reads on hand-built maps, with every expected value worked by hand."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from alte.lab.studies.analysis.tradeoff import (
    equal_fidelity,
    equal_size,
    fronts,
    interval_table,
    matching,
    read_at_size,
    size_for_fidelity,
)

FRONT_COLUMNS = ["terrain", "mapper", "seed", "params", "x", "y", "on_front"]


def _maps(terrain: str, mapper: str, seed: int, sizes: list[float],
          errors: list[float]) -> list[dict]:
    return [{"terrain": terrain, "mapper": mapper, "seed": seed, "params": f"p{i}",
             "basis_functions": n, "mhd_m": e, "completeness": 1.0 - e}
            for i, (n, e) in enumerate(zip(sizes, errors, strict=True))]


def test_fronts_list_every_map_sorted_with_its_flag() -> None:
    rows = (_maps("t2", "quadtree", 0, [10, 20], [2.0, 1.0])
            + _maps("t1", "quadtree", 1, [10, 20, 40], [2.0, 3.0, 1.0])
            + _maps("t1", "alte2d", 0, [0.0, 0.5, 30], [0.1, 0.5, 0.2]))
    marked = fronts(pd.DataFrame(rows))
    assert list(marked.columns) == FRONT_COLUMNS and list(marked.index) == list(range(8))
    got = list(marked.itertuples(index=False, name=None))
    assert got == [
        # a map of size zero is never on a front; 0.5 is a size like any other
        ("t1", "alte2d", 0, "p0", 0.0, 0.1, False),
        ("t1", "alte2d", 0, "p1", 0.5, 0.5, True),
        ("t1", "alte2d", 0, "p2", 30.0, 0.2, True),
        ("t1", "quadtree", 1, "p0", 10.0, 2.0, True),
        ("t1", "quadtree", 1, "p1", 20.0, 3.0, False),  # larger and worse than p0
        ("t1", "quadtree", 1, "p2", 40.0, 1.0, True),
        ("t2", "quadtree", 0, "p0", 10.0, 2.0, True),
        ("t2", "quadtree", 0, "p1", 20.0, 1.0, True)]
    assert marked["on_front"].dtype == bool and marked["x"].dtype == np.float64


def test_a_front_of_a_higher_is_better_metric_keeps_the_highest() -> None:
    rows = _maps("t1", "quadtree", 0, [10, 20, 40], [0.5, 0.2, 0.6])  # completeness .5 .8 .4
    marked = fronts(pd.DataFrame(rows), metric="completeness", higher_is_better=True)
    assert marked["on_front"].tolist() == [True, True, False]
    lower = fronts(pd.DataFrame(rows), metric="completeness")
    assert lower["on_front"].tolist() == [True, False, True]


def test_fronts_of_no_maps_is_an_empty_table_with_the_columns() -> None:
    empty = pd.DataFrame(columns=["terrain", "mapper", "seed", "params", "basis_functions",
                                  "mhd_m"])
    marked = fronts(empty)
    assert marked.empty and list(marked.columns) == FRONT_COLUMNS


def test_matching_a_parameter_the_table_lacks_matches_no_row() -> None:
    rows = pd.DataFrame({"p_max_points": [10, 20, "auto"]}, index=[5, 6, 7])
    none = matching(rows, {"depth": 3})
    assert none.tolist() == [False, False, False] and list(none.index) == [5, 6, 7]
    assert matching(rows, {"max_points": 20}).tolist() == [False, True, False]  # text: no match


def test_reads_off_an_empty_front_are_nan_per_level() -> None:
    empty = np.array([], dtype=float)
    for read in (read_at_size(empty, empty, [1.0, 2.0]), size_for_fidelity(empty, empty, [1.0])):
        assert read.dtype == np.float64 and np.isnan(read).all()
    assert len(read_at_size(empty, empty, [1.0, 2.0])) == 2


def test_a_one_map_front_is_read_at_its_own_size_and_error_only() -> None:
    xs, ys = np.array([100.0]), np.array([0.5])
    assert size_for_fidelity(xs, ys, [0.5]) == pytest.approx([100.0])
    assert np.isnan(size_for_fidelity(xs, ys, [0.4, 0.6])).all()
    assert read_at_size(xs, ys, [100.0]) == pytest.approx([0.5])
    # flat up to the largest map made
    assert read_at_size(xs, ys, [100.0, 1000.0, 2000.0], x_max=1000.0)[:2] == pytest.approx(
        [0.5, 0.5])


def _pair(sizes_b: list[float], errors_b: list[float], terrain: str = "t1") -> list[dict]:
    return (_maps(terrain, "quadtree", 0, [100, 1000, 10000], [4.0, 2.0, 1.0])
            + _maps(terrain, "alte2d", 0, sizes_b, errors_b))


def test_equal_size_levels_lie_at_a_fifth_half_and_four_fifths_in_log_size() -> None:
    table = pd.DataFrame(_pair([100, 10000], [2.0, 0.5]))
    reads = equal_size(table, ("quadtree", "alte2d"))
    # shared sizes 100..10000: 10^2.4 = 251 -> 250, 10^3 = 1000, 10^3.6 = 3981 -> 4000
    assert sorted(set(reads["level"])) == [250.0, 1000.0, 4000.0]
    at_1000 = reads[reads["level"] == 1000.0].set_index("mapper")["value"]
    assert at_1000["quadtree"] == pytest.approx(2.0)
    assert at_1000["alte2d"] == pytest.approx(1.25)  # halfway in log size from 2.0 to 0.5
    given = equal_size(table, ("quadtree", "alte2d"), levels=[1000.0])
    assert given["level"].tolist() == [1000.0, 1000.0]


def test_equal_fidelity_levels_lie_inside_the_errors_every_front_reaches() -> None:
    table = pd.DataFrame(_pair([100, 10000], [2.0, 0.5]))
    reads = equal_fidelity(table, ("quadtree", "alte2d"))
    # errors reached by both: 1.0 .. 2.0 -> 1.2, 1.5, 1.8
    assert sorted(set(reads["level"])) == pytest.approx([1.2, 1.5, 1.8])
    at = reads[np.isclose(reads["level"], 1.5)].set_index("mapper")["value"]
    # quadtree: 1.5 is halfway from 2.0 (1000) to 1.0 (10000) -> 10^3.5
    assert at["quadtree"] == pytest.approx(10**3.5)
    # alte2d: 1.5 is a third of the way from 2.0 (100) to 0.5 (10000) -> 10^(2 + 2/3)
    assert at["alte2d"] == pytest.approx(10 ** (2 + 2 / 3))
    given = equal_fidelity(table, ("quadtree", "alte2d"), levels=[1.5])
    assert given["level"].tolist() == [1.5, 1.5]


def test_equal_fidelity_on_a_higher_is_better_metric() -> None:
    table = pd.DataFrame(_pair([100, 10000], [2.0, 0.5]))
    table["completeness"] = 1.0 - table["mhd_m"] / 10  # quadtree .6 .8 .9, alte2d .8 .95
    reads = equal_fidelity(table, ("quadtree", "alte2d"), fidelity="completeness",
                           higher_is_better=True, levels=[0.85])
    at = reads.set_index("mapper")["value"]
    assert at["quadtree"] == pytest.approx(10**3.5)  # halfway from .8 (1000) to .9 (10000)
    assert at["alte2d"] == pytest.approx(10 ** (2 + 2 / 3))  # a third from .8 to .95
    auto = equal_fidelity(table, ("quadtree", "alte2d"), fidelity="completeness",
                          higher_is_better=True)
    assert sorted(set(auto["level"])) == pytest.approx([0.82, 0.85, 0.88])  # within .8 .. .9


def test_a_terrain_without_every_mapper_is_skipped_not_the_ones_after_it() -> None:
    rows = _maps("t0", "quadtree", 0, [100, 1000], [2.0, 1.0]) + _pair([100, 10000], [2.0, 0.5])
    reads = equal_size(pd.DataFrame(rows), ("quadtree", "alte2d"), levels=[1000.0])
    assert set(reads["terrain"]) == {"t1"}


def test_reads_come_sorted_by_terrain() -> None:
    rows = _pair([100, 10000], [2.0, 0.5], "t2") + _pair([100, 10000], [2.0, 0.5], "t1")
    reads = equal_size(pd.DataFrame(rows), ("quadtree", "alte2d"), levels=[1000.0])
    assert reads["terrain"].tolist() == ["t1", "t1", "t2", "t2"]


def test_the_interval_table_is_sorted_reproducible_and_keyed() -> None:
    values = [1.0, 2.0, 6.0, 3.0, 7.0, 0.5, 4.0, 0.5]  # mean 3 over eight seeds
    reads = pd.DataFrame({"terrain": ["t2"] + ["t1"] * 8, "level": 1.0,
                          "mapper": "quadtree", "seed": [0, *range(8)],
                          "value": [5.0, *values]})
    table = interval_table(reads)
    assert list(table.columns) == ["terrain", "level", "mapper", "mean", "low", "high", "seeds"]
    assert table["terrain"].tolist() == ["t1", "t2"]
    assert table["mean"].tolist() == pytest.approx([3.0, 5.0])
    assert table["seeds"].tolist() == [8, 1]
    pd.testing.assert_frame_equal(table, interval_table(reads, seed=0))
    pd.testing.assert_frame_equal(table, interval_table(reads))
    assert not table.equals(interval_table(reads, seed=1))
