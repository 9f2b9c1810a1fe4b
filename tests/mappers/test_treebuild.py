"""Tests of the tree build's walk (``alte.mappers.quad.treebuild``): the walk split over
threads gives the single walk's cells bit for bit."""

from __future__ import annotations

import numpy as np
import pytest

from alte.mappers.quad.treebuild import sort_points, tree_cells


def clustered_points(n: int, bits: int, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Finest keys below ``2**bits``, clustered (dense patches, repeated keys, lone
    points) as a terrain's are, and two values per point."""
    rng = np.random.default_rng(seed)
    centres = rng.integers(0, 1 << bits, 40)
    spread = rng.integers(1, 1 << max(1, bits // 2), 40)
    which = rng.integers(0, 40, n)
    keys = np.clip(centres[which] + rng.integers(-1, 2, n) * rng.integers(0, spread[which]),
                   0, (1 << bits) - 1)
    keys[: n // 10] = rng.integers(0, 1 << bits, n // 10)  # scattered lone points
    values = np.column_stack([rng.normal(0, 1, n), rng.uniform(-3, 3, n)])
    return keys.astype(np.int64), values


def same(a: list[tuple[np.ndarray, ...]], b: list[tuple[np.ndarray, ...]]) -> bool:
    return len(a) == len(b) and all(
        x.dtype == y.dtype and x.tobytes() == y.tobytes()
        for level_a, level_b in zip(a, b, strict=True)
        for x, y in zip(level_a, level_b, strict=True))


@pytest.mark.parametrize(("depth", "split_above"), [(12, 25.0), (12, 1.0), (9, 200.0),
                                                    (2, 5.0), (12, 1e9)])
def test_walk_on_threads_equals_one_walk_bit_for_bit(depth: int, split_above: float) -> None:
    keys, values = clustered_points(70_000, 2 * depth)
    points = sort_points(keys, values, 2 * depth)
    one = tree_cells(points, depth, split_above, threads=1)
    assert sum(len(level[0]) for level in one) > 1 or split_above > 1e6
    for threads in (2, 3, 8):
        assert same(tree_cells(points, depth, split_above, threads=threads), one)


def test_walk_of_one_cell_below_the_split_level() -> None:
    """All points in one cell of the split level (one group busy, the others empty)."""
    keys, values = clustered_points(70_000, 8)
    points = sort_points(keys, values, 24)
    assert same(tree_cells(points, 12, 3.0, threads=2), tree_cells(points, 12, 3.0, threads=1))


@pytest.mark.parametrize(("n", "bits"), [(100, 24), (20_000, 24), (70_000, 24), (70_000, 7),
                                         (70_000, 40), (70_000, 13)])
def test_sort_points_is_numpys_stable_sort(n: int, bits: int) -> None:
    """Small inputs, one radix sort, and a cloud's split by its top 6 bits: the packed
    keys in stable key order, with the values they index."""
    keys, values = clustered_points(n, bits, seed=n + bits)
    packed, shift, kept = sort_points(keys.copy(), values, bits)
    order = np.argsort(keys, kind="stable")
    assert shift and kept is not None
    assert np.array_equal(packed >> shift, keys[order])
    assert np.array_equal(packed & ((1 << shift) - 1), order)
    again, _, _ = sort_points(keys.copy(), values, bits, reuse_keys=True)
    assert np.array_equal(again, packed)
