"""The compiled cell-statistics kernels give numpy's results bit for bit."""

from __future__ import annotations

import numpy as np
import pytest

from alte.mappers.quad.cellstats import (
    aggregate_points,
    combine,
    fill_index,
    merge_cells,
    sort_keys,
)


def _starts(keys: np.ndarray) -> np.ndarray:
    return np.flatnonzero(np.r_[True, keys[1:] != keys[:-1]])


def _numpy_aggregate(keys: np.ndarray, values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    starts = _starts(keys)
    counts = np.diff(np.r_[starts, len(values)]).astype(np.float64)
    mean = np.add.reduceat(values, starts, axis=0) / counts[:, None]
    dev = values - np.repeat(mean, counts.astype(np.int64), axis=0)
    m2 = np.add.reduceat(dev * dev, starts, axis=0)
    rows = np.column_stack([counts, mean, m2, np.maximum.reduceat(values, starts, axis=0)])
    return keys[starts], rows


def _numpy_pair(a: np.ndarray, b: np.ndarray, nv: int) -> np.ndarray:
    na, nb = a[:, :1], b[:, :1]
    n = na + nb
    delta = b[:, 1:1 + nv] - a[:, 1:1 + nv]
    mean = a[:, 1:1 + nv] + delta * (nb / n)
    m2 = a[:, 1 + nv:1 + 2 * nv] + b[:, 1 + nv:1 + 2 * nv] + delta * delta * (na * nb / n)
    return np.column_stack([n, mean, m2, np.maximum(a[:, 1 + 2 * nv:], b[:, 1 + 2 * nv:])])


@pytest.mark.parametrize(("n", "bits"), [(0, 20), (1, 20), (100, 20), (40_000, 0),
                                         (40_000, 7), (40_000, 20), (40_000, 24), (40_000, 48)])
def test_sort_keys_is_numpys_stable_argsort(n, bits) -> None:
    keys = np.random.default_rng(n).integers(0, 1 << bits, n)
    keys[: n // 3] = keys[0] if n else 0  # long runs of ties
    got, order = sort_keys(keys, bits)
    assert np.array_equal(order, np.argsort(keys, kind="stable"))
    assert np.array_equal(got, np.sort(keys, kind="stable"))


@pytest.mark.parametrize("per_cell", [1, 7, 9, 130, 300])
def test_aggregate_points_is_numpys_reduceat(per_cell) -> None:
    """Runs short and long (numpy's pairwise sum switches at 8 and 128 terms)."""
    rng = np.random.default_rng(per_cell)
    keys = np.sort(rng.integers(0, 2000 // per_cell + 1, 2000))
    values = rng.normal(100.0, 3.0, (2000, 2))
    got_keys, got = aggregate_points(keys, values)
    want_keys, want = _numpy_aggregate(keys, values)
    assert np.array_equal(got_keys, want_keys)
    assert np.array_equal(got, want)


def test_combine_groups_children_by_parent() -> None:
    rng = np.random.default_rng(5)
    keys = np.unique(rng.integers(0, 4096, 900))
    _, rows = aggregate_points(np.repeat(keys, 3), rng.normal(0, 1, (3 * len(keys), 1)))
    parents, merged = combine(keys, rows, 1)
    assert np.array_equal(parents, np.unique(keys >> 2))
    for p, row in zip(parents[:50], merged[:50], strict=True):
        kids = rows[(keys >> 2) == p]
        acc = kids[:1]
        for kid in kids[1:]:  # sequential Chan merges agree to rounding
            acc = _numpy_pair(acc, kid[None], 1)
        assert np.allclose(acc[0], row, rtol=1e-12, atol=1e-12)
        assert row[0] == kids[:, 0].sum()


def _ordered_sum(terms: list[float]) -> float:
    """``x[0] + (x[1] + ... + x[m-1])``: np.add.reduceat's order on a short run."""
    if len(terms) == 1:
        return terms[0]
    rest = terms[1]
    for term in terms[2:]:
        rest += term
    return terms[0] + rest


def test_combine_is_chans_merge_in_reduceat_order_bit_for_bit() -> None:
    """Python floats (IEEE doubles) in the documented order give the kernel's rows exactly."""
    rng = np.random.default_rng(8)
    keys = np.unique(rng.integers(0, 1 << 12, 1500))
    counts = rng.integers(1, 6, len(keys)).astype(np.float64)
    rows = np.column_stack([counts, rng.normal(7.0, 3.0, (len(keys), 2)),
                            rng.uniform(0.0, 2.0, (len(keys), 2))])  # n, means, m2 (nv 2)
    rows = np.column_stack([rows, rows[:, 1:3] + 1.0])  # max
    parents, merged = combine(keys, rows, 2)
    for p, got in zip(parents, merged, strict=True):
        kids = [list(map(float, r)) for r in rows[(keys >> 2) == p]]
        count = _ordered_sum([k[0] for k in kids])
        want = [count]
        for j in (1, 2):
            mean = _ordered_sum([k[0] * k[j] for k in kids]) / count
            want.append(mean)
            want.append(_ordered_sum([k[2 + j] + k[0] * (k[j] - mean) * (k[j] - mean)
                                      for k in kids]))
            want.append(max(k[4 + j] for k in kids))
        assert got.tolist() == [want[0], want[1], want[4], want[2], want[5], want[3], want[6]]


@pytest.mark.parametrize("dense", [True, False])
def test_merge_cells_updates_known_and_appends_new(dense) -> None:
    rng = np.random.default_rng(9)
    old_keys = np.unique(rng.integers(0, 1000, 300))
    _, old_rows = aggregate_points(old_keys, rng.normal(0, 1, (len(old_keys), 2)))
    new_keys = np.unique(rng.integers(0, 1000, 200))
    _, new_rows = aggregate_points(new_keys, rng.normal(0, 1, (len(new_keys), 2)))
    cap = len(old_keys) + len(new_keys)
    skeys = np.zeros(cap, np.int64)
    srows = np.zeros((cap, old_rows.shape[1]))
    split = np.ones(cap, bool)
    skeys[: len(old_keys)], srows[: len(old_keys)] = old_keys, old_rows
    index = np.zeros(1024, np.int32) if dense else np.full(2 * 2048, -1, np.int64)
    fill_index(index, skeys, len(old_keys), dense)
    store = (skeys, srows, split, index)
    touched, n = merge_cells(store, len(old_keys), (new_keys, new_rows), 2, dense)
    assert n == len(np.union1d(old_keys, new_keys))
    assert np.array_equal(skeys[touched], new_keys)
    known = np.isin(new_keys, old_keys)
    want = _numpy_pair(old_rows[np.searchsorted(old_keys, new_keys[known])], new_rows[known], 2)
    assert np.array_equal(srows[touched[known]], want)
    assert np.array_equal(srows[touched[~known]], new_rows[~known])
    assert not split[touched[~known]].any()
