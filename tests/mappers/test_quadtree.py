"""Tests of the Quadtree mapper and the shared 2D machinery (quadgrid, quadmap)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from support.maps import assert_partition, same_cells

from alte.errors import MapperError, ParameterError
from alte.mappers.domain import Domain
from alte.mappers.quad import levelstats
from alte.mappers.quad.levelstats import LevelStats
from alte.mappers.quad.quadgrid import Square, morton_decode, morton_encode
from alte.mappers.quad.quadmap import plane_height
from alte.mappers.quadtree import Quadtree

DOMAIN = Domain(0.0, 0.0, 0.0, 16.0)
coords = st.floats(0.0, 16.0, allow_nan=False, width=32)
clouds = arrays(np.float64, st.tuples(st.integers(1, 120), st.just(3)), elements=coords)


def box_terrain(n: int = 4000, seed: int = 0) -> np.ndarray:
    """Flat ground at z=0 on [0,16]^2 with a 3 m box on [4,8]x[4,8]."""
    rng = np.random.default_rng(seed)
    xy = rng.uniform(0, 16, (n, 2))
    box = (xy[:, 0] > 4) & (xy[:, 0] < 8) & (xy[:, 1] > 4) & (xy[:, 1] < 8)
    return np.column_stack([xy, np.where(box, 3.0, 0.0) + rng.normal(0, 0.02, n)])


def test_morton_round_trip() -> None:
    ix = np.array([0, 1, 5, 2**20 - 1, 12345])
    iy = np.array([0, 7, 3, 2**20 - 3, 999])
    x, y = morton_decode(morton_encode(ix, iy))
    assert np.array_equal(x, ix) and np.array_equal(y, iy)


@settings(max_examples=40, deadline=None)
@given(clouds, st.integers(1, 20), st.integers(0, 6))
def test_partition_counts_and_limits(points, max_points, max_depth) -> None:
    qt = Quadtree(max_points=max_points, max_depth=max_depth, domain=DOMAIN)
    qt.build(points)
    cells, counts = qt.cells(), qt.leaf_counts()
    assert_partition(cells)
    assert counts.sum() == len(points)
    assert (cells.level <= max_depth).all()
    assert (counts[cells.level < max_depth] <= max_points).all()
    assert np.isnan(cells.value[counts == 0]).all()
    assert not cells.occupied[counts == 0].any()
    assert qt.basis_functions == len(cells)


@settings(max_examples=30, deadline=None)
@given(clouds, st.integers(1, 10), st.integers(1, 5), st.randoms(use_true_random=False))
def test_incremental_equals_batch_and_order_invariant(points, max_points, splits, rnd) -> None:
    batch = Quadtree(max_points=max_points, max_depth=6, domain=DOMAIN)
    batch.build(points)
    order = list(range(len(points)))
    rnd.shuffle(order)
    incr = Quadtree(max_points=max_points, max_depth=6, domain=DOMAIN)
    for chunk in np.array_split(points[order], splits):
        incr.insert(chunk, np.zeros(3))
    assert same_cells(batch.cells(), incr.cells())
    batch.stats.complete()  # a build keeps the tree's cells; insertions keep every cell
    for level in range(7):  # the merged statistics (n, means, M2, max) match too
        assert np.array_equal(batch.stats.keys[level], incr.stats.keys[level])
        assert np.allclose(batch.stats.rows[level], incr.stats.rows[level], atol=1e-9)


def assert_tree_of_every_cell(points: np.ndarray, max_points: int, max_depth: int) -> None:
    """The tree a build keeps (root, children of split cells) holds the very rows, keys
    and flags of those cells among every level's cells (an insertion's); completed, the
    built map holds every cell, bit for bit; memory counts what is held."""
    built = Quadtree(max_points=max_points, max_depth=max_depth, domain=DOMAIN)
    built.build(points)
    tree = [(built.stats.keys[lv], built.stats.rows[lv], built.stats.split[lv])
            for lv in range(max_depth + 1)]
    cells, tree_bytes = built.cells(), built.memory_bytes
    full = Quadtree(max_points=max_points, max_depth=max_depth, domain=DOMAIN)
    full.insert(points, np.zeros(3))
    for level, (keys, rows, split) in enumerate(tree):
        parents = full.stats.keys[level - 1][full.stats.split[level - 1]] if level else [0]
        kept = np.isin(full.stats.keys[level] >> (2 if level else 0), parents)
        assert np.array_equal(full.stats.keys[level][kept], keys)
        assert np.array_equal(full.stats.rows[level][kept], rows)
        assert np.array_equal(full.stats.split[level][kept], split)
    assert same_cells(cells, full.cells())
    built.stats.complete()
    for level in range(max_depth + 1):
        assert np.array_equal(built.stats.rows[level], full.stats.rows[level])
        assert np.array_equal(built.stats.split[level], full.stats.split[level])
    assert built.memory_bytes == full.memory_bytes
    # a cell: key, n, 3 statistics of 2 values, flag; a kept point: packed key, 2 values
    assert tree_bytes == 65 * sum(len(keys) for keys, _, _ in tree) + 24 * len(points)


@settings(max_examples=30, deadline=None)
@given(clouds, st.integers(1, 10), st.integers(0, 7))
def test_build_keeps_the_trees_cells_bit_for_bit(points, max_points, max_depth) -> None:
    assert_tree_of_every_cell(points, max_points, max_depth)


def test_build_of_equal_pairs_splits_to_max_depth() -> None:
    """Pairs of equal points under max_points 1: every cell holding a pair splits, down
    to max_depth (a tree of long chains, more cells than points)."""
    pairs = np.repeat(np.random.default_rng(1).uniform(0, 16, (300, 3)), 2, axis=0)
    assert_tree_of_every_cell(pairs, 1, 12)


def test_insert_after_build_equals_batch() -> None:
    """Frames inserted into a built map (its levels completed first) give the batch map
    of all points."""
    pts = box_terrain(3000, seed=4)
    later = box_terrain(1500, seed=5) * (1.5, 1.5, 1.0) - (2.0, 3.0, 0.0)  # some outside
    qt = Quadtree(max_points=15, max_depth=9, domain=DOMAIN)
    qt.build(pts)
    for chunk in np.array_split(later, 4):
        qt.insert(chunk, np.zeros(3))
    batch = Quadtree(max_points=15, max_depth=9, domain=DOMAIN)
    batch.build(np.vstack([pts, later]))
    assert same_cells(qt.cells(), batch.cells())
    assert qt.points_inserted == batch.points_inserted < len(pts) + len(later)


def test_growth_after_build_sees_every_cell() -> None:
    """A root that grows after a build (no domain) shifts the completed levels: the same
    map, bit for bit, as when the build had kept every cell."""
    pts = box_terrain(3000, seed=4)
    later = np.array_split(box_terrain(1500, seed=5) * (1.5, 1.5, 1.0) - (2.0, 3.0, 0.0), 4)
    lazy, eager = Quadtree(max_points=15, max_depth=9), Quadtree(max_points=15, max_depth=9)
    lazy.build(pts)
    eager.build(pts)
    eager.stats.complete()
    for chunk in later:
        lazy.insert(chunk, np.zeros(3))
        eager.insert(chunk, np.zeros(3))
    assert lazy.square == eager.square and lazy.square.size > 2 * 16
    for level in range(10):
        assert np.array_equal(lazy.stats.keys[level], eager.stats.keys[level])
        assert np.array_equal(lazy.stats.rows[level], eager.stats.rows[level])
        assert np.array_equal(lazy.stats.split[level], eager.stats.split[level])


def test_growth_without_domain_equals_batch_on_grown_root() -> None:
    pts = box_terrain() - (3.3, 1.7, 0.0)
    sweep = pts[np.argsort(-pts[:, 0] - 0.5 * pts[:, 1])]
    incr = Quadtree(max_points=50)
    sizes = []
    for chunk in np.array_split(sweep, 10):
        incr.insert(chunk, np.zeros(3))
        sizes.append(incr.square.size)
    sq = incr.square
    assert sizes[-1] >= 4 * sizes[0]  # the root grew at least twice
    assert incr.points_outside == 0
    batch = Quadtree(max_points=50, domain=Domain(sq.xmin, sq.ymin, 0.0, sq.size))
    batch.build(pts)
    assert same_cells(incr.cells(), batch.cells())


def test_occupancy_marks_the_box_and_leaves_ground_free() -> None:
    qt = Quadtree(max_points=20, height_threshold=1.0, domain=DOMAIN)
    qt.build(box_terrain())
    cells = qt.cells()
    on_box = (np.abs(cells.centers[:, 0] - 6) < 2) & (np.abs(cells.centers[:, 1] - 6) < 2)
    assert cells.occupied[on_box & (cells.sizes[:, 0] < 1)].mean() > 0.9
    far = (np.abs(cells.centers[:, 0] - 6) > 3) | (np.abs(cells.centers[:, 1] - 6) > 3)
    assert not cells.occupied[far].any()
    corners = qt.corners()  # set B: every known leaf at its height, ground and box alike
    known = np.isfinite(cells.centers[:, 2])
    assert set(np.round(corners[:, 2], 6)) == set(np.round(cells.centers[known, 2], 6))
    assert np.isclose(corners[:, 2], 3.0, atol=0.2).any() and np.isclose(corners[:, 2], 0.0,
                                                                           atol=0.2).any()


def test_mean_rule_averages_a_small_obstacle_away_but_max_keeps_it() -> None:
    pts = np.array([[1.0, 1.0, 0.0]] * 9 + [[1.5, 1.5, 2.0]])
    mean = Quadtree(domain=Domain(0, 0, 0, 4), occupancy="mean", height_threshold=0.5)
    mean.build(pts)
    mx = Quadtree(domain=Domain(0, 0, 0, 4), occupancy="max", height_threshold=0.5)
    mx.build(pts)
    assert mean.cells().occupied.sum() == 0
    assert mx.cells().occupied.sum() == 1


def test_ground_plane_and_fit() -> None:
    rng = np.random.default_rng(2)
    xy = rng.uniform(0, 16, (3000, 2))
    z = 0.1 * xy[:, 0] + 1.0 + rng.normal(0, 0.01, 3000)
    pts = np.column_stack([xy, z])
    flat = Quadtree(domain=DOMAIN, height_threshold=0.5)
    flat.build(pts)
    assert flat.cells().occupied.any()  # the slope rises over z=0
    tilted = Quadtree(domain=DOMAIN, height_threshold=0.5, ground="-0.1,0,1,-1")
    tilted.build(pts)
    assert not tilted.cells().occupied.any()
    fitted = Quadtree(domain=DOMAIN, height_threshold=0.5, ground="fit")
    fitted.build(pts)
    assert not fitted.cells().occupied.any()
    assert np.allclose(fitted.plane[:3] / fitted.plane[2], [-0.1, 0, 1], atol=0.01)


def test_heights_above_a_tilted_plane_are_numpys() -> None:
    """The compiled values (z, height above the plane) are the numpy expression's, bit
    for bit, so that maps do not depend on which computed them."""
    pts = box_terrain(2000, seed=6) * (3.1, 0.7, 1.3)
    qt = Quadtree(ground="0.13,-0.21,0.97,0.37")
    above = pts[:, 2] - plane_height(qt.plane, pts[:, :2])
    assert np.array_equal(qt._values(pts), np.column_stack([pts[:, 2], above]))


def test_points_outside_fixed_domain_are_counted() -> None:
    qt = Quadtree(domain=Domain(0, 0, 0, 1))
    qt.insert(np.array([[0.5, 0.5, 0.0], [3.0, 0.5, 0.0]]), np.zeros(3))
    assert qt.points_outside == 1 and qt.leaf_counts().sum() == 1


def test_empty_map_and_empty_frames() -> None:
    qt = Quadtree()
    qt.insert(np.empty((0, 3)), np.zeros(3))
    assert len(qt.cells()) == 0 and len(qt.corners()) == 0
    fixed = Quadtree(domain=DOMAIN)
    assert len(fixed.cells()) == 1 and np.isnan(fixed.cells().value[0])
    assert fixed.memory_bytes == 0  # nothing inserted: no cell is held


def test_memory_counts_each_held_cell_at_its_cost() -> None:
    """A held cell costs its 8-byte key, its row of statistics (8 bytes for the count
    and 3 x 8 for each of the two values it keeps: 56) and a 1-byte split flag."""
    per_cell = 8 + 8 * (1 + 3 * 2) + 1
    levels = 13  # max_depth 12: one cell per level down to the point's leaf
    one = Quadtree(domain=Domain(0, 0, 0, 8))
    one.insert(np.array([[1.0, 1.0, 0.5]]), np.zeros(3))
    assert one.memory_bytes == levels * per_cell
    two = Quadtree(domain=Domain(0, 0, 0, 8), max_points=1)
    two.insert(np.array([[1.0, 1.0, 0.5], [7.0, 7.0, 1.0]]), np.zeros(3))
    # the root holds both points; below it, each point its own cell on every level
    assert two.memory_bytes == (1 + 2 * (levels - 1)) * per_cell


@pytest.mark.parametrize(("key", "value", "match"), [
    ("max_points", 0, "max_points"),
    ("max_depth", 25, "max_depth"),
    ("max_depth", -1, "max_depth"),
    ("height_threshold", -1.0, "height_threshold"),
    ("occupancy", "median", "occupancy"),
    ("ground", "0,0,0,1", "ground"),
    ("ground", "a,b", "ground"),
    ("colour", 1, "unknown parameter.*valid: "),
])
def test_bad_parameters(key, value, match) -> None:
    with pytest.raises(ParameterError, match=match):
        Quadtree(**{key: value})


@pytest.mark.parametrize(("points", "match"), [
    (np.zeros((3, 2)), "shape"),
    (np.array([[0.0, np.nan, 0.0]]), "NaN"),
])
def test_bad_points(points, match) -> None:
    with pytest.raises(MapperError, match=match):
        Quadtree().build(points)
    with pytest.raises(MapperError, match=match):
        Quadtree(domain=DOMAIN).insert(points, np.zeros(3))


def test_bad_origin_and_fit_on_insert() -> None:
    with pytest.raises(MapperError, match="origin"):
        Quadtree().insert(np.zeros((1, 3)), np.array([np.inf, 0, 0]))
    with pytest.raises(MapperError, match="ground=fit"):
        Quadtree(ground="fit").insert(np.zeros((1, 3)), np.zeros(3))
    with pytest.raises(MapperError, match="ground=fit"):
        Quadtree(ground="fit").build(np.zeros((2, 3)))


@pytest.mark.parametrize(("first_capacity", "dense_cells"), [(1, 0), (50, 64), (1 << 22, 1 << 24)])
def test_pending_cells_fold_to_the_same_statistics(monkeypatch, first_capacity,
                                                   dense_cells) -> None:
    """Folded after every frame or only at the end, whatever the storage growth and the
    index (hashed, dense on coarse levels only, dense): same map."""
    pts = box_terrain(3000, seed=3)
    frames = np.array_split(pts[np.argsort(pts[:, 0])], 15)  # new cells on every frame
    monkeypatch.setattr(levelstats, "_FIRST_CAPACITY", first_capacity)
    monkeypatch.setattr(levelstats, "_DENSE_CELLS", dense_cells)
    eager = Quadtree(max_points=10, max_depth=7, domain=DOMAIN)
    lazy = Quadtree(max_points=10, max_depth=7, domain=DOMAIN)
    for frame in frames:
        eager.insert(frame, np.zeros(3))
        eager.cells()  # a reader folds the pending cells
        lazy.insert(frame, np.zeros(3))
    assert same_cells(eager.cells(), lazy.cells())
    assert lazy.memory_bytes == eager.memory_bytes
    for level in range(8):  # bit-identical statistics, flags and order
        assert np.array_equal(eager.stats.keys[level], lazy.stats.keys[level])
        assert np.array_equal(eager.stats.rows[level], lazy.stats.rows[level])
        assert np.array_equal(eager.stats.split[level], lazy.stats.split[level])
        assert (np.diff(lazy.stats.keys[level]) > 0).all()


def test_deferred_rows_are_the_ones_add_returned() -> None:
    stats = LevelStats(3, 1)
    sq = Square(0.0, 0.0, 16.0)
    first = box_terrain(500, seed=1)
    stats.add(sq.keys(first[:, :2], 3), first[:, 2:])
    frame = box_terrain(200, seed=2)
    keys = sq.keys(frame[:, :2], 3)
    with stats.deferred():
        touched = stats.add(keys, frame[:, 2:])
        assert np.array_equal(stats.keys[3][touched[3]], np.unique(keys))
        assert np.array_equal(stats.keys[1][touched[1]], np.unique(keys >> 4))
    assert (np.diff(stats.keys[3]) > 0).all()  # folded once read outside
    assert stats.column(0, "n")[0] == 700


def test_split_flags_need_one_per_cell() -> None:
    stats = LevelStats(2, 1)
    stats.add(np.array([0, 5, 9]), np.zeros((3, 1)))
    stats.split[2] = np.array([True, False, True])
    assert stats.split[2].tolist() == [True, False, True]
    with pytest.raises(MapperError, match=r"level 2: .* for 3 cells"):
        stats.split[2] = np.zeros(2, bool)


def test_build_of_a_whole_cloud_keeps_the_trees_cells_bit_for_bit() -> None:
    """A cloud large enough for the build's per-point kernels and walk to run on every
    thread (``alte._numba.CLOUD_MIN``) keeps the insertion's cells as a small one does."""
    assert_tree_of_every_cell(box_terrain(80_000, seed=3), 25, 10)
