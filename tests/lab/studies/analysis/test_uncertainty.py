"""Seed bootstrap: percentile intervals, reproducible, honest with one seed."""

from __future__ import annotations

import numpy as np
import pytest

from alte.lab.studies.analysis.uncertainty import bootstrap_ci, bootstrap_columns


def test_interval_brackets_the_mean_and_is_reproducible():
    values = np.array([1.0, 2.0, 4.0, 3.0, 2.5])
    a, b = bootstrap_ci(values, seed=3), bootstrap_ci(values, seed=3)
    assert a == b
    assert a.estimate == pytest.approx(2.5)
    assert a.low < a.estimate < a.high
    assert a.seeds == 5 and a.level == 0.95
    assert bootstrap_ci(values, level=0.5).high - bootstrap_ci(values, level=0.5).low < (
        a.high - a.low)


def test_nan_values_are_dropped_and_one_seed_has_no_width():
    one = bootstrap_ci([np.nan, 2.0])
    assert (one.estimate, one.low, one.high, one.seeds) == (2.0, 2.0, 2.0, 1)
    none = bootstrap_ci([np.nan])
    assert none.seeds == 0 and np.isnan(none.estimate)
    same = bootstrap_ci([1.5, 1.5, 1.5])
    assert (same.low, same.high, same.seeds) == (1.5, 1.5, 3)


def test_bootstrap_columns_matches_one_interval_per_column_in_spirit():
    rng = np.random.default_rng(0)
    data = rng.normal(loc=[1.0, 5.0, 9.0], size=(6, 3))
    mean, low, high = bootstrap_columns(data)
    assert mean == pytest.approx(data.mean(axis=0))
    assert (low < mean).all() and (mean < high).all() and (high - low < 3).all()
    flat = bootstrap_columns(np.array([[1.0, 2.0], [1.0, 3.0]]))
    assert flat[1][0] == flat[2][0] == 1.0 and flat[1][1] < flat[2][1]
    one = bootstrap_columns(np.array([[1.0, 2.0]]))
    assert one[1].tolist() == one[2].tolist() == [1.0, 2.0]
