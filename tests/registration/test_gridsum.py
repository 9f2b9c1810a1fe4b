"""The voxel grid's numba kernels give numpy's values to the last bit.

A registered cloud is a sum of thousands of scan points per cell; a sum in another order
differs in its last bits, and odometry fitted to the cloud then drifts elsewhere. So the
kernels are checked bit for bit against the numpy code they replace, on cells of 1 to
600 points (numpy's pairwise summation changes form at 8 and 128 values), values of
mixed magnitude (where the order of additions shows) and signed zeros.
"""

from __future__ import annotations

import numpy as np
import pytest

from alte._kernels import bounds
from alte.registration.grid import GridAccumulator, grid_average_with_counts
from alte.registration.gridsum import gathered_sums, pack, unpack


def _cells(rng: np.random.Generator, sizes: list[int]) -> np.ndarray:
    """Integer keys (N, 3), shuffled, with a cell of each of ``sizes`` rows."""
    keys = np.concatenate([np.tile(rng.integers(-50, 50, 3), (size, 1)) for size in sizes])
    return keys[rng.permutation(len(keys))]


def _numpy_sort(keys: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The packed sort as numpy did it (min/max, pack with the row number, divmod)."""
    low, high = keys.min(axis=0), keys.max(axis=0)
    span = [int(h) - int(lo) + 1 for lo, h in zip(low, high, strict=True)]
    shifted = keys - low
    code = (shifted[:, 0] * span[1] + shifted[:, 1]) * span[2] + shifted[:, 2]
    code = code * len(keys) + np.arange(len(keys))
    code.sort()
    code, order = np.divmod(code, len(keys))
    return order, np.flatnonzero(np.r_[True, code[1:] != code[:-1]])


def _bits(values: np.ndarray) -> np.ndarray:
    return np.ascontiguousarray(values, dtype=np.float64).view(np.int64)


@pytest.mark.parametrize("seed", range(4))
def test_packed_sort_is_numpys(seed: int) -> None:
    rng = np.random.default_rng(seed)
    keys = _cells(rng, list(rng.integers(1, 40, 300)))
    low, high = bounds(keys)
    assert np.array_equal(low, keys.min(axis=0)) and np.array_equal(high, keys.max(axis=0))
    span = (high - low + 1).astype(np.int64)
    code = pack(keys, low, span)
    code.sort()
    order, starts = unpack(code)
    expected = _numpy_sort(keys)
    assert np.array_equal(order, expected[0]) and np.array_equal(starts, expected[1])


def test_negative_zeros_keep_their_sign() -> None:
    """A one-row cell is copied, and numpy's sums start from -0.0, not 0.0."""
    values = np.array([[-0.0, 1.0, -0.0], [5.0, 1.0, -0.0], [-0.0, -0.0, -0.0]])
    out, _ = gathered_sums(values, np.ones(3), np.arange(3), np.array([0, 1], np.int64))
    assert np.signbit(out).tolist() == [[True, False, True], [False, False, True]]
    assert np.array_equal(_bits(out), _bits(np.add.reduceat(values, [0, 1], axis=0)))


def test_a_registered_cloud_is_the_numpy_grids() -> None:
    """Scans accumulated frame by frame (with folds) against the same sums by numpy."""
    rng = np.random.default_rng(7)
    frames = [rng.normal(scale=20.0, size=(3000, 3)) for _ in range(12)]
    acc = GridAccumulator(0.5)
    for frame in frames:
        acc.add(frame)
    cloud = np.concatenate(frames)
    keys = np.floor(cloud / 0.5).astype(np.int64)
    order, starts = _numpy_sort(keys)
    sums = np.add.reduceat(cloud[order], starts, axis=0)
    counts = np.add.reduceat(np.ones(len(cloud))[order], starts)
    assert np.array_equal(acc.counts(), counts)
    # folding sums partial sums, so the cloud is compared to within rounding here and
    # bit for bit per frame below
    assert np.allclose(acc.points(), sums / counts[:, None], rtol=0, atol=1e-12)
    keys_one, sums_one, counts_one = grid_average_with_counts(frames[0], 0.5)
    k0 = np.floor(frames[0] / 0.5).astype(np.int64)
    order, starts = _numpy_sort(k0)
    assert np.array_equal(keys_one, k0[order[starts]])
    assert np.array_equal(_bits(sums_one), _bits(np.add.reduceat(frames[0][order], starts,
                                                                 axis=0)))
    assert np.array_equal(counts_one, np.add.reduceat(np.ones(3000)[order], starts))


@pytest.mark.parametrize("seed", range(4))
def test_gathered_sums_are_reduceat_of_the_gathered_rows(seed: int) -> None:
    """Summing through the order (no gathered copy) gives ``np.add.reduceat`` of the
    gathered rows to the last bit, for every run length numpy's summation changes at."""
    rng = np.random.default_rng(seed)
    sizes = [1, 2, 7, 8, 9, 16, 17, 128, 129, 130, 257, 600, *rng.integers(1, 300, 40)]
    keys = _cells(rng, sizes)
    n = len(keys)
    values = rng.normal(size=(n, 3)) * 10.0 ** rng.integers(-6, 7, (n, 3))
    values[rng.random((n, 3)) < 0.05] = -0.0
    counts = rng.integers(1, 5, n) * 10.0 ** rng.integers(-3, 4, n)
    order, starts = _numpy_sort(keys)
    got, got_counts = gathered_sums(values, counts, order, starts)
    assert np.array_equal(_bits(got), _bits(np.add.reduceat(values[order], starts, axis=0)))
    assert np.array_equal(_bits(got_counts), _bits(np.add.reduceat(counts[order], starts)))
