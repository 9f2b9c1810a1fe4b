"""``Mapper.reread``: a map fed once, read with other view parameters, equals the map made
with them (cells, counts, corners, size), and the fed map and its copies refuse points."""

from __future__ import annotations

import numpy as np
import pytest

from alte.errors import MapperError, ParameterError
from alte.mappers import make_mapper
from alte.mappers._rows import row_groups, unique_rows
from alte.mappers.domain import Domain

DOMAIN = Domain(-5.0, -5.0, -2.0, 64.0)


def _frames(n: int = 6, seed: int = 1) -> list[tuple[np.ndarray, np.ndarray]]:
    """Scans of a bumpy ground with a box on it, each seen from its own origin."""
    rng = np.random.default_rng(seed)
    out = []
    for k in range(n):
        xy = rng.uniform(0, 50, (3000, 2))
        z = 0.3 * np.sin(xy[:, 0] / 4) + rng.normal(0, 0.04, len(xy))
        z[(np.abs(xy[:, 0] - 20) < 4) & (np.abs(xy[:, 1] - 30) < 6)] += 3.0
        out.append((np.c_[xy, z], np.array([25.0, 25.0 + k, 30.0])))
    return out


def _fed(mapper: str, params: dict[str, object]):
    m = make_mapper(mapper, params, domain=DOMAIN)
    for points, origin in _frames():
        m.insert(points, origin)
    return m


def _same_map(a, b) -> None:
    ca, cb = a.cells(), b.cells()
    for field in ("centers", "sizes", "value", "occupied", "level"):
        assert np.array_equal(getattr(ca, field), getattr(cb, field), equal_nan=True), field
    assert a.basis_functions == b.basis_functions and a.memory_bytes == b.memory_bytes
    assert np.array_equal(a.corners(), b.corners())
    assert a.params == b.params


CASES = [
    ("alte3d", {"max_res": 6, "min_pts_split": 20, "min_pts": 10},
     [{"min_pts_split": 5}, {"min_pts": 40}, {"occupancy_level": 0, "min_pts": 5},
      {"min_pts_split": 80, "min_pts": 20}]),
    ("alte2d", {"kappa": 0.1, "max_res": 6, "min_pts": 10},
     [{"kappa": 0.003}, {"kappa": 3.0, "min_pts": 100}, {"min_pts": 2}]),
    ("quadtree", {"max_points": 50}, [{"occupancy": "max"}, {"height_threshold": 0.1}]),
]


@pytest.mark.parametrize(("mapper", "base", "views"), CASES)
def test_reread_equals_the_map_made_with_those_parameters(mapper, base, views):
    fed = _fed(mapper, base)
    before = fed.cells()
    for change in views:
        _same_map(fed.reread(**change), _fed(mapper, {**base, **change}))
    _same_map(fed, _fed(mapper, base))  # the fed map still reads as before
    assert fed.cells() is before or np.array_equal(fed.cells().centers, before.centers,
                                                   equal_nan=True)


def test_reread_of_a_batch_built_quadtree():
    cloud = np.vstack([p for p, _ in _frames()])
    built = make_mapper("quadtree", {"max_points": 25}, domain=DOMAIN)
    built.build(cloud)
    fresh = make_mapper("quadtree", {"max_points": 25, "occupancy": "max"}, domain=DOMAIN)
    fresh.build(cloud)
    _same_map(built.reread(occupancy="max"), fresh)


@pytest.mark.parametrize(("mapper", "base", "views"), CASES)
def test_fed_map_and_copy_refuse_points_until_rebuilt(mapper, base, views):
    fed = _fed(mapper, base)
    copy = fed.reread(**views[0])
    points, origin = _frames(1, seed=5)[0]
    for m in (fed, copy):
        with pytest.raises(MapperError, match=r"re-read with other parameters .* afresh"):
            m.insert(points, origin)
    copy.build(points)  # a build starts afresh: nothing shared any more
    assert copy.basis_functions > 0


@pytest.mark.parametrize(("mapper", "change", "match"), [
    ("alte3d", {"max_res": 5}, r"alte3d: max_res change\(s\) what the map stores; a map can "
                               r"be re-read with other min_pts, min_pts_split, occupancy_level"),
    ("alte2d", {"criterion": "binev"}, r"alte2d: criterion change\(s\) .* kappa, min_pts only"),
    ("quadtree", {"max_points": 9}, r"quadtree: max_points change\(s\) what the map stores"),
    ("octomap", {"resolution": 2.0}, r"octomap: resolution .* other none only"),
])
def test_reread_refuses_stored_parameters(mapper, change, match):
    m = make_mapper(mapper, {}, domain=None if mapper == "octomap" else DOMAIN)
    with pytest.raises(MapperError, match=match):
        m.reread(**change)


def test_reread_checks_values_and_octomap_is_itself():
    m = _fed("alte3d", {"max_res": 4})
    with pytest.raises(ParameterError, match="alte3d: min_pts=0 out of range"):
        m.reread(min_pts=0)
    octo = make_mapper("octomap", {"resolution": 2.0})
    assert octo.reread() is octo


def test_unique_rows_is_numpys_unique():
    rng = np.random.default_rng(3)
    lo = rng.integers(-50, 50, (4000, 3)) * 0.37 + 0.1
    size = 0.37 * (1 << rng.integers(0, 3, 4000))[:, None]
    offsets = np.array([[i >> 2 & 1, i >> 1 & 1, i & 1] for i in range(8)], dtype=np.float64)
    corners = (lo[:, None, :] + offsets[None] * size[:, None, :]).reshape(-1, 3)
    corners[:7] = 0.0
    corners[3:7] *= -1.0  # -0.0 rows: one row with them
    for pts in (corners, np.rint(corners * 8).astype(np.int64), corners[:1], corners[:0]):
        assert np.array_equal(unique_rows(pts), np.unique(pts, axis=0).reshape(-1, 3))


def test_row_groups_is_numpys_unique_with_inverse():
    rng = np.random.default_rng(5)
    half = 0.25 * (1 << rng.integers(0, 4, (3000, 3))).astype(np.float64)
    half[::7] = [0.5, 0.25, 1.0]
    for pts in (half, half[:1], half[:0], half[:, :2], np.rint(half * 4).astype(np.int64)):
        rows, inverse = row_groups(pts)
        want, where = np.unique(pts, axis=0, return_inverse=True)
        assert np.array_equal(rows, want.reshape(-1, pts.shape[1]))
        assert np.array_equal(inverse, where.reshape(-1)) and inverse.shape == (len(pts),)
