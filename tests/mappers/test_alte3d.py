"""Tests of 3D-ALTE: partition, counts, incremental == batch, occupancy rule, variants."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from alte.errors import MapperError, ParameterError
from alte.mappers.alte3d import Alte3D
from alte.mappers.domain import Domain

DOMAIN = Domain(0.0, 0.0, 0.0, 8.0)
coords = arrays(np.float64, st.tuples(st.integers(1, 300), st.just(3)),
                elements=st.floats(0.0, 8.0, allow_nan=False))


def _terrain(n: int, seed: int = 0) -> np.ndarray:
    """A gently waving ground (100 m square) plus a dense wall."""
    rng = np.random.default_rng(seed)
    xy = rng.uniform(0, 100, (n, 2))
    ground = np.c_[xy, 0.2 * np.sin(xy[:, 0] / 10) + rng.normal(0, 0.05, n)]
    wall = np.c_[rng.uniform(20, 22, n // 5), rng.uniform(10, 60, n // 5),
                 rng.uniform(0, 15, n // 5)]
    return np.vstack([ground, wall])


def _finest_cover(cells, max_res: int, size: float) -> np.ndarray:
    """Index of every finest-level cell covered by each leaf (with repeats if overlapping)."""
    n = 1 << max_res
    edge = size / n
    lo = np.rint((cells.centers - cells.sizes / 2) / edge).astype(int)
    side = np.rint(cells.sizes / edge).astype(int)
    out = []
    for corner, s in zip(lo, side, strict=True):
        grid = np.stack(np.meshgrid(*[np.arange(c, c + k) for c, k in zip(corner, s, strict=True)],
                                    indexing="ij"), -1).reshape(-1, 3)
        out.append((grid[:, 0] * n + grid[:, 1]) * n + grid[:, 2])
    return np.concatenate(out)


@settings(max_examples=30, deadline=None)
@given(coords, st.integers(0, 3), st.integers(1, 5))
def test_leaves_partition_the_domain_and_counts_add_up(points, max_res, split):
    mapper = Alte3D(max_res=max_res, min_pts_split=split, domain=DOMAIN)
    mapper.build(points)
    cells = mapper.cells()
    assert np.prod(cells.sizes, axis=1).sum() == pytest.approx(8.0**3)
    cover = _finest_cover(cells, max_res, 8.0)
    assert cover.size == np.unique(cover).size == 8**max_res  # no overlap, no gap
    assert cells.value.sum() == points.shape[0]
    assert cells.level.max() <= max_res
    assert (cells.value[cells.level < max_res] <= split).all()
    assert mapper.basis_functions == len(cells)


@settings(max_examples=30, deadline=None)
@given(coords, st.integers(1, 6), st.randoms(use_true_random=False))
def test_incremental_equals_batch_and_order_does_not_matter(points, frames, rnd):
    batch = Alte3D(max_res=3, min_pts_split=3, min_pts=2, domain=DOMAIN)
    batch.build(points)
    order = np.arange(points.shape[0])
    rnd.shuffle(order)
    incremental = Alte3D(max_res=3, min_pts_split=3, min_pts=2, domain=DOMAIN)
    for part in np.array_split(points[order], frames):
        incremental.insert(part, np.zeros(3))
    a, b = batch.cells(), incremental.cells()
    for name in ("centers", "sizes", "value", "occupied", "level"):
        ia, ib = np.lexsort(a.centers.T), np.lexsort(b.centers.T)
        np.testing.assert_array_equal(getattr(a, name)[ia], getattr(b, name)[ib])


def _coverage(cells, points: np.ndarray, domain: tuple) -> float:
    """Fraction of ``points`` inside an occupied cell (level by level, vectorised)."""
    origin, size = np.array(domain[:3]), domain[3]
    covered = np.zeros(points.shape[0], bool)
    for level in np.unique(cells.level):
        edge = size / 2.0**level
        pick = cells.occupied & (cells.level == level)
        occ = np.floor((cells.centers[pick] - origin) / edge).astype(np.int64)
        idx = np.floor((points - origin) / edge).astype(np.int64)
        pack = np.array([1 << 40, 1 << 20, 1])
        covered |= np.isin(idx @ pack, occ @ pack)
    return float(covered.mean())


def test_coarse_max_res_gives_an_incomplete_map():
    points, domain = _terrain(60000), (0, 0, -5, 105)
    coverage = {}
    for max_res in (4, 6):
        mapper = Alte3D(max_res=max_res, domain=Domain(*domain))
        mapper.build(points)
        coverage[max_res] = _coverage(mapper.cells(), points, domain)
    assert coverage[6] > 0.9
    assert coverage[4] < 0.5 * coverage[6]


def test_plain_count_rule_when_occupancy_level_is_zero():
    points = np.full((12, 3), 1.0)
    mapper = Alte3D(max_res=2, min_pts=10, min_pts_split=50, occupancy_level=0, domain=DOMAIN)
    mapper.build(points)
    assert mapper.cells().occupied.sum() == 1  # the root: 12 >= 10, never split
    aware = Alte3D(max_res=2, min_pts=10, min_pts_split=50, domain=DOMAIN)
    aware.build(points)
    assert not aware.cells().occupied.any()  # a level-0 cell would need 10 * 8**6 points


def test_fixed_altitude_splits_only_horizontally():
    rng = np.random.default_rng(3)
    points = np.c_[rng.uniform(0, 8, (500, 2)), rng.uniform(0, 2.5, 500)]
    mapper = Alte3D(variant="fixed_altitude", cell_height=0.5, max_res=3, min_pts_split=5,
                    min_pts=1, occupancy_level=0, domain=DOMAIN)
    mapper.build(points)
    cells = mapper.cells()
    np.testing.assert_allclose(cells.sizes[:, 2], 0.5)
    np.testing.assert_allclose(cells.sizes[:, 0], 8.0 / 2.0**cells.level)
    assert np.prod(cells.sizes, axis=1).sum() == pytest.approx(64 * 0.5 * 5)  # 5 layers
    assert cells.value.sum() == 500


def test_corners_of_one_occupied_cell():
    mapper = Alte3D(max_res=1, min_pts=1, min_pts_split=100, occupancy_level=0, domain=DOMAIN)
    mapper.build(np.array([[1.0, 1.0, 1.0]]))
    corners = mapper.corners()
    assert corners.shape == (8, 3)
    np.testing.assert_allclose(np.unique(corners), [0.0, 8.0])


def test_build_uses_the_bounding_cube_and_memory_grows_with_data():
    mapper = Alte3D(max_res=6)
    terrain = _terrain(20000)
    mapper.build(terrain)
    dom = mapper.domain
    assert dom is not None
    xmin, ymin, size = dom.xmin, dom.ymin, dom.size
    assert size >= 100 * 0.99 and xmin >= 0 and ymin >= 0
    large = mapper.memory_bytes
    mapper.build(np.vstack([terrain[:200] * 0.05, terrain.max(axis=0)]))  # same cube, clustered
    assert 0 < mapper.memory_bytes < large / 5


@pytest.mark.parametrize(("params", "match"), [
    ({"max_res": -1}, "max_res"),
    ({"max_res": 17}, "max_res"),
    ({"min_pts": 0}, "min_pts"),
    ({"min_pts_split": 0}, "min_pts_split"),
    ({"occupancy_level": 20}, "occupancy_level"),
    ({"variant": "sphere"}, "variant"),
    ({"cell_height": 0}, "cell_height"),
    ({"max_res": 2.5}, "integer"),
    ({"kappa": 1}, "unknown parameter"),
])
def test_bad_parameters_raise(params, match):
    with pytest.raises(ParameterError, match=match):
        Alte3D(**params)


def test_domain_is_typed():
    assert Alte3D(domain=DOMAIN).domain == DOMAIN
    with pytest.raises(MapperError, match=r"domain must be an alte\.mappers\.Domain"):
        Alte3D(domain="0,0,0,8")  # type: ignore[arg-type]


def test_points_outside_the_domain_are_counted_not_raised():
    mapper = Alte3D(domain=DOMAIN, max_res=1, min_pts=1, min_pts_split=100)
    mapper.insert(np.array([[9.0, 1.0, 1.0], [1.0, 1.0, 1.0], [1.0, 1.0, -0.5]]), np.zeros(3))
    assert mapper.points_outside == 2
    assert int(mapper.cells().value.sum()) == 1


def test_bad_inputs_raise():
    with pytest.raises(MapperError, match="fixed domain"):
        Alte3D().insert(np.zeros((2, 3)), np.zeros(3))
    with pytest.raises(MapperError, match="shape"):
        Alte3D(domain=DOMAIN).insert(np.zeros((2, 2)), np.zeros(3))
    with pytest.raises(MapperError, match="NaN"):
        Alte3D().build(np.array([[np.nan, 0.0, 0.0]]))
    with pytest.raises(MapperError, match="origin"):
        Alte3D(domain=DOMAIN).insert(np.zeros((2, 3)), np.zeros(2))
    with pytest.raises(MapperError, match="empty cloud"):
        Alte3D().build(np.zeros((0, 3)))
