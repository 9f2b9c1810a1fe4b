"""Tests of the 2D-ALTE mapper (thesis 3.3.1)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from support.maps import assert_partition, same_cells

from alte.errors import MapperError, ParameterError
from alte.mappers.alte2d import Alte2D, plane_height
from alte.mappers.domain import Domain
from alte.paths import realdata_dir

DOMAIN = Domain(0.0, 0.0, 0.0, 16.0)
coords = st.floats(0.0, 16.0, allow_nan=False, width=32)
clouds = arrays(np.float64, st.tuples(st.integers(1, 120), st.just(3)), elements=coords)
criteria = st.sampled_from(["thesis", "binev"])


def step_terrain(n: int = 3000, seed: int = 0) -> np.ndarray:
    """Ground at z=0 with a 2 m step on x > 8 (domain [0,16]^2)."""
    rng = np.random.default_rng(seed)
    xy = rng.uniform(0, 16, (n, 2))
    return np.column_stack([xy, np.where(xy[:, 0] > 8, 2.0, 0.0) + rng.normal(0, 0.01, n)])


@settings(max_examples=40, deadline=None)
@given(clouds, st.integers(0, 5), st.integers(1, 10), criteria,
       st.floats(1e-3, 10.0))
def test_partition_counts_limits_and_means(points, max_res, min_pts, criterion, kappa) -> None:
    m = Alte2D(max_res=max_res, min_pts=min_pts, criterion=criterion, kappa=kappa, domain=DOMAIN)
    m.build(points)
    cells, counts = m.cells(), m.leaf_counts()
    assert_partition(cells)
    assert counts.sum() == len(points)
    assert (cells.level <= max_res).all()
    assert np.array_equal(np.isnan(cells.value), counts == 0)
    assert np.array_equal(cells.occupied, counts > 0)
    # a split parent had at least min_pts points: every non-root leaf's siblings hold >= min_pts
    level, keys, _rows = m.stats.leaves()
    for lev in range(1, max_res + 1):
        parents = np.unique(keys[level == lev] >> 2)
        n = m.stats.column(lev - 1, "n")[np.searchsorted(m.stats.keys[lev - 1], parents)]
        assert (n >= min_pts).all()


def test_value_is_the_mean_height_of_the_cell() -> None:
    pts = step_terrain(500)
    m = Alte2D(max_res=3, min_pts=5, kappa=0.01, domain=DOMAIN)
    m.build(pts)
    cells = m.cells()
    for c, s, v in zip(cells.centers, cells.sizes, cells.value, strict=True):
        inside = (np.abs(pts[:, 0] - c[0]) <= s[0] / 2) & (np.abs(pts[:, 1] - c[1]) <= s[1] / 2)
        if inside.any():
            assert np.isclose(v, pts[inside, 2].mean(), atol=1e-9)


def test_thesis_criterion_is_the_sum_of_squares_against_kappa() -> None:
    rng = np.random.default_rng(3)
    xy = rng.uniform(0, 16, (400, 2))
    z = rng.normal(0, 0.5, 400)
    pts = np.column_stack([xy, z])
    sse = ((z - z.mean()) ** 2).sum()
    low = Alte2D(kappa=0.99 * sse, max_res=1, min_pts=1, domain=DOMAIN)
    low.build(pts)
    high = Alte2D(kappa=1.01 * sse, max_res=1, min_pts=1, domain=DOMAIN)
    high.build(pts)
    few = Alte2D(kappa=0.5 * sse, max_res=1, min_pts=401, domain=DOMAIN)
    few.build(pts)
    assert len(low.cells()) == 4 and len(high.cells()) == 1 and len(few.cells()) == 1


def test_binev_tree_holds_the_ancestors_of_marked_cells() -> None:
    """Every quadrant holds the same step, so the root's children share one mean:
    the root's own indicator is 0, yet it splits because its children are marked."""
    rng = np.random.default_rng(5)
    xy = rng.uniform(0, 16, (4000, 2))
    z = np.where(np.mod(xy[:, 0], 8) > 4, 1.0, 0.0)
    m = Alte2D(criterion="binev", kappa=1.0, max_res=3, min_pts=10, domain=DOMAIN)
    m.build(np.column_stack([xy, z]))
    assert m._binev_indicator(0, np.array([0]))[0] < 1e-3
    cells = m.cells()
    assert len(cells) > 4 and (cells.level >= 2).all()


def test_binev_criterion_matches_its_formula() -> None:
    pts = step_terrain(1000)
    m = len(pts)
    c = pts[:, 2].mean()
    eps = 0.0
    for qx in (0, 1):
        for qy in (0, 1):
            sel = ((pts[:, 0] >= 8) == qx) & ((pts[:, 1] >= 8) == qy)
            eps += sel.sum() * (pts[sel, 2].mean() - c) ** 2 / m
    tau_unit = np.sqrt(np.log(m) / m)
    below = Alte2D(criterion="binev", kappa=0.99 * eps / tau_unit, max_res=1, domain=DOMAIN)
    below.build(pts)
    above = Alte2D(criterion="binev", kappa=1.01 * eps / tau_unit, max_res=1, domain=DOMAIN)
    above.build(pts)
    assert len(below.cells()) == 4 and len(above.cells()) == 1


def test_step_is_resolved_and_flat_ground_stays_coarse() -> None:
    pts = step_terrain(6000)
    pts[:, 2] = np.where(pts[:, 0] > 5, 2.0, 0.0) + (pts[:, 2] - np.round(pts[:, 2]))
    m = Alte2D(kappa=1.0, max_res=5, min_pts=10, domain=DOMAIN)
    m.build(pts)
    cells = m.cells()
    left = cells.centers[:, 0] + cells.sizes[:, 0] / 2 <= 5
    right = cells.centers[:, 0] - cells.sizes[:, 0] / 2 >= 5
    assert (left | right).all()  # no leaf straddles the step
    assert np.allclose(cells.value[left], 0.0, atol=0.05)
    assert np.allclose(cells.value[right], 2.0, atol=0.05)
    assert (cells.level[cells.centers[:, 0] > 9] <= 2).all()  # flat ground stays coarse
    assert 4 < m.basis_functions < 100


@settings(max_examples=30, deadline=None)
@given(clouds, criteria, st.integers(1, 5), st.randoms(use_true_random=False))
def test_incremental_equals_batch_and_order_invariant(points, criterion, splits, rnd) -> None:
    kw = {"criterion": criterion, "kappa": 0.5, "min_pts": 3, "max_res": 5, "domain": DOMAIN}
    batch = Alte2D(**kw)
    batch.build(points)
    order = list(range(len(points)))
    rnd.shuffle(order)
    incr = Alte2D(**kw)
    for chunk in np.array_split(points[order], splits):
        incr.insert(chunk, np.zeros(3))
    assert same_cells(batch.cells(), incr.cells())
    assert np.allclose(batch.cells().value, incr.cells().value, equal_nan=True)


@pytest.mark.parametrize("criterion", ["thesis", "binev"])
def test_growth_without_domain_equals_batch_on_grown_root(criterion) -> None:
    pts = step_terrain() + np.array([5.1, -2.7, 0.0])
    incr = Alte2D(criterion=criterion, kappa=0.01)
    first = None
    for chunk in np.array_split(pts[np.argsort(pts[:, 0] + pts[:, 1])], 16):
        incr.insert(chunk, np.zeros(3))
        first = first or incr.square.size
    sq = incr.square
    assert sq.size >= 2 * first
    batch = Alte2D(criterion=criterion, kappa=0.01, domain=Domain(sq.xmin, sq.ymin, 0.0, sq.size))
    batch.build(pts)
    assert same_cells(incr.cells(), batch.cells())


def test_occupancy_grid_and_unknown_cells() -> None:
    pts = step_terrain()
    pts = pts[pts[:, 1] < 8]  # upper half unseen
    m = Alte2D(kappa=0.01, max_res=4, domain=DOMAIN)
    m.build(pts)
    grid = m.occupancy_grid(1.0, ground=0.0)
    cells = m.cells()
    unknown = np.isnan(cells.value)
    assert unknown.any() and not grid.occupied[unknown].any()
    assert np.isnan(grid.value[unknown]).all()
    known = ~unknown
    assert np.array_equal(grid.occupied[known], cells.centers[known, 2] > 1.0)
    tilted = m.occupancy_grid(1.0, ground=np.array([-0.25, 0.0, 1.0, 0.0]))  # z = x / 4
    assert tilted.occupied.sum() < grid.occupied.sum()
    corners = m.corners()
    assert len(corners) > 0 and set(np.round(corners[:, 2])) <= {0.0, 2.0}


def test_plane_height() -> None:
    xy = np.array([[0.0, 0.0], [2.0, 4.0]])
    assert np.allclose(plane_height(1.5, xy), 1.5)
    assert np.allclose(plane_height(np.array([1.0, 0.0, 2.0, -2.0]), xy), [1.0, 0.0])
    with pytest.raises(ValueError, match="non-vertical"):
        plane_height(np.array([1.0, 0.0, 0.0, 1.0]), xy)


@pytest.mark.parametrize(("key", "value", "match"), [
    ("kappa", 0.0, "kappa"),
    ("kappa", "nan", "kappa"),
    ("max_res", 21, "max_res"),
    ("max_res", "six", "max_res"),
    ("max_res", 2.5, "max_res"),
    ("min_pts", 0, "min_pts"),
    ("criterion", "variance", "criterion"),
    ("tau", 1, "unknown parameter.*valid: criterion, kappa, max_res, min_pts"),
])
def test_bad_parameters(key, value, match) -> None:
    with pytest.raises(ParameterError, match=match):
        Alte2D(**{key: value})


def test_string_parameters_are_coerced() -> None:
    m = Alte2D(kappa="0.5", max_res="4", min_pts="20", criterion="binev", domain=Domain(0, 0, 0, 8))
    assert m.params.as_dict() == {"kappa": 0.5, "max_res": 4, "min_pts": 20,
                                  "criterion": "binev"}
    assert m.domain == Domain(0, 0, 0, 8)
    assert m.square.size == 8


@pytest.mark.parametrize(("points", "match"), [
    (np.zeros(3), "shape"),
    (np.array([[0.0, 0.0, np.inf]]), "NaN or inf"),
])
def test_bad_points(points, match) -> None:
    with pytest.raises(MapperError, match=match):
        Alte2D().build(points)
    with pytest.raises(MapperError, match=match):
        Alte2D().insert(points, np.zeros(3))
    with pytest.raises(MapperError, match="origin"):
        Alte2D().insert(np.zeros((2, 3)), np.zeros(2))


REALDATA = realdata_dir()


@pytest.mark.realdata
def test_isprs_airborne_sample() -> None:
    """Real ALS terrain (ISPRS samp11): leaves stop only by the criterion or the limits,
    and inserting the strips in file order gives the batch map."""
    path = REALDATA / "isprs_terrain" / "samp11-utm.pcd"
    if not path.is_file():
        pytest.skip(f"{path} absent")
    from alte.io.points.pointfiles import read_points

    pts = read_points(path)
    pts = pts - pts.min(axis=0)
    kw = {"kappa": 5.0, "max_res": 7, "min_pts": 10}
    batch = Alte2D(**kw)
    batch.build(pts)
    level, _keys, rows = batch.stats.leaves()
    n = batch.leaf_stat(level, rows, "n")
    m2 = batch.leaf_stat(level, rows, "m2")
    free = (level < 7) & (n >= 10)
    assert free.any() and (m2[free] <= 5.0).all()
    assert 50 < batch.basis_functions < 4**7
    sq = batch.square
    incr = Alte2D(**kw, domain=Domain(sq.xmin, sq.ymin, 0.0, sq.size))
    for chunk in np.array_split(pts, 10):
        incr.insert(chunk, np.zeros(3))
    assert same_cells(batch.cells(), incr.cells())
