"""The Kalman update against hand-computed cases, the gate and the per-cell statistics."""

import numpy as np
import pytest
from alte_elevation import CellState, Gate, fuse

GATE = Gate(threshold=2.5, multi_height_noise=0.01)


def _one_cell(z: list[float], r: list[float], state: CellState | None = None,
              gate: Gate = GATE) -> CellState:
    return fuse(state or CellState.empty(), np.zeros(len(z), np.int64), np.array(z),
                np.array(r), gate)


def test_kalman_update_by_hand() -> None:
    """Prior h = 1.0 m, v = 0.04 m^2; a point z = 1.1 m with r = 0.01 m^2:
    h' = (v z + r h) / (v + r) = (0.04 * 1.1 + 0.01 * 1.0) / 0.05 = 1.08 m,
    v' = v r / (v + r) = 0.0004 / 0.05 = 0.008 m^2."""
    prior = _one_cell([1.0], [0.04])
    assert prior.height[0] == 1.0 and prior.variance[0] == pytest.approx(0.04)
    after = _one_cell([1.1], [0.01], prior)
    assert after.height[0] == pytest.approx(1.08)
    assert after.variance[0] == pytest.approx(0.008)
    # A second point of the same scan, z = 0.9, r = 0.01, from the same prior: the
    # information form gives 1/v' = 1/0.04 + 2/0.01 = 225, h' = (1/0.04 + 1.1/0.01 +
    # 0.9/0.01) / 225 = 225 / 225 = 1.0 m.
    both = _one_cell([1.1, 0.9], [0.01, 0.01], prior)
    assert both.variance[0] == pytest.approx(1 / 225)
    assert both.height[0] == pytest.approx(1.0)


def test_scan_equals_sequential_updates() -> None:
    """Fusing a scan at once equals the Kalman updates one point at a time (all accepted)."""
    rng = np.random.default_rng(1)
    z, r = 2.0 + rng.normal(0, 0.02, 20), rng.uniform(0.0004, 0.002, 20)
    h, v = z[0], r[0]
    for zi, ri in zip(z[1:], r[1:], strict=True):
        h, v = (v * zi + ri * h) / (v + ri), v * ri / (v + ri)
    state = _one_cell(list(z), list(r), gate=Gate(threshold=100.0))
    assert state.height[0] == pytest.approx(h) and state.variance[0] == pytest.approx(v)


def test_gate_rejects_and_inflates() -> None:
    """A point 1 m off a cell sure to 0.1 m fails the 2.5 sigma gate: the height stays,
    the variance grows by multi_height_noise, and min/max still see it."""
    prior = _one_cell([0.0], [0.01])
    after = _one_cell([1.0], [0.0001], prior)  # innovation sigma ~0.1005: 9.95 sigma off
    assert after.height[0] == 0.0
    assert after.variance[0] == pytest.approx(0.01 + GATE.multi_height_noise)
    assert (after.low[0], after.high[0], after.points[0]) == (0.0, 1.0, 2.0)
    assert after.m2[0] == pytest.approx(0.5)  # the spread sees the rejected point


def test_new_cell_starts_from_its_first_point() -> None:
    """In the scan that first sees a cell, its first point is the prior and the others
    are gated against it (the outlier at 5 m is rejected)."""
    state = _one_cell([0.0, 0.02, 5.0], [0.01, 0.01, 0.01])
    assert state.height[0] == pytest.approx(0.01)
    assert state.variance[0] == pytest.approx(0.005 + GATE.multi_height_noise)
    assert state.high[0] == 5.0


def test_cells_stay_sorted_and_separate() -> None:
    keys = np.array([7, 3, 7, 11, 3], np.int64)
    z = np.array([1.0, 2.0, 1.0, 3.0, 2.0])
    state = fuse(CellState.empty(), keys, z, np.full(5, 0.01), GATE)
    assert state.keys.tolist() == [3, 7, 11]
    assert state.height.tolist() == pytest.approx([2.0, 1.0, 3.0])
    state = fuse(state, np.array([5, 11], np.int64), np.array([4.0, 3.0]), np.full(2, 0.01),
                 GATE)
    assert state.keys.tolist() == [3, 5, 7, 11]
    assert state.points.tolist() == [2, 1, 2, 2]
    assert state.variance[3] == pytest.approx(0.005)


def test_a_scan_merged_into_many_cells_keeps_each_cell_as_if_fused_alone() -> None:
    """Scans of many cells, old and new interleaved (new keys before the first, between
    and after the old ones): every cell holds exactly what fusing its own points alone
    gives, so the merge put each value in its own cell's place."""
    rng = np.random.default_rng(3)
    scans = [rng.integers(-50, 50, 300).astype(np.int64) * 3 + offset for offset in (0, 1, -2)]
    state = CellState.empty()
    alone: dict[int, CellState] = {}
    for keys in scans:
        z, r = rng.normal(size=len(keys)), rng.uniform(0.01, 0.1, len(keys))
        state = fuse(state, keys, z, r, GATE)
        for key in np.unique(keys):
            mine = keys == key
            alone[int(key)] = fuse(alone.get(int(key), CellState.empty()),
                                   np.zeros(int(mine.sum()), np.int64), z[mine], r[mine], GATE)
    assert state.keys.tolist() == sorted(alone)
    for name in ("height", "variance", "low", "high", "points", "mean", "m2", "noise"):
        assert getattr(state, name).tolist() == pytest.approx(
            [getattr(alone[k], name)[0] for k in state.keys.tolist()], rel=1e-12), name


def test_spread_is_the_surface_beyond_the_noise() -> None:
    """Heights 0, 0.2, 0.4 with r = 0.001 (gated or not): sample variance 0.08/3, less the
    mean noise 0.001."""
    state = _one_cell([0.0, 0.2, 0.4], [0.001] * 3)
    assert state.m2[0] == pytest.approx(0.08)
    assert state.spread()[0] == pytest.approx(0.08 / 3 - 0.001)
    # Merged over two scans (Chan): the same.
    two = _one_cell([0.4], [0.001], _one_cell([0.0, 0.2], [0.001] * 2, gate=Gate(threshold=1e6)),
                    gate=Gate(threshold=1e6))
    assert two.m2[0] == pytest.approx(0.08) and two.mean[0] == pytest.approx(0.2)
