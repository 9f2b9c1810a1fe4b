"""Tests of the Octomap mapper: native backend against the C++ reference, .bt, parameters."""

from __future__ import annotations

import bz2

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from alte.errors import AlteError, MapperError, ParameterError
from alte.mappers.octomap import Octomap, compare_backends, read_bt
from alte.mappers.octomap.backends import logodds
from alte.mappers.octomap.voxelstore import PAGE, VoxelStore
from alte.mappers.octree.blockset import WORDS, keys_to_blocks
from alte.mappers.octree.raycast import morton_encode
from alte.mappers.octree.tree import Leaves, prune, prune_voxels
from alte.paths import realdata_dir

REALDATA = realdata_dir() / "octomap_scan"
BACKENDS = ["native", "reference"]


def _scene(origin: np.ndarray, seed: int, n: int = 600) -> np.ndarray:
    """Ground plane plus a wall, as seen from ``origin`` (noisy, deterministic)."""
    rng = np.random.default_rng(seed)
    ground = np.c_[rng.uniform(-4, 4, (n, 2)), np.zeros(n)]
    wall = np.c_[np.full(n // 3, 2.5), rng.uniform(-2, 2, n // 3), rng.uniform(0, 2, n // 3)]
    return np.vstack([ground, wall]) + rng.normal(0, 0.01, (n + n // 3, 3))


ORIGINS = [np.array([0, 0, 2.0]), np.array([1, 1, 2.5]), np.array([-2, 1, 1.5])]
SCANS = [(_scene(o, i), o) for i, o in enumerate(ORIGINS)]


def _leaf_set(mapper: Octomap) -> set:
    leaves = mapper.leaves()
    return set(zip(leaves.prefix.tolist(), leaves.depth.tolist(), leaves.value.tolist(),
                   strict=True))


@pytest.mark.parametrize("params", [
    {"resolution": 5},
    {"resolution": 10, "max_range": 2.5},
    {"resolution": 4, "sensor_model": "octomap", "max_range": 3.7},
    {"resolution": 7.3, "sensor_model": "octomap"},
])
def test_native_equals_reference_on_multi_scan_scene(params):
    native, reference = Octomap(**params), Octomap(backend="reference", **params)
    for points, origin in SCANS:
        native.insert(points, origin)
        reference.insert(points, origin)
    assert native.basis_functions == reference.basis_functions
    assert _leaf_set(native) == _leaf_set(reference)  # same leaves, depths, log-odds


def test_compare_backends_reports_agreement():
    out = compare_backends(SCANS, resolution=5)
    assert out["jaccard"] == 1.0
    assert out["leaf_count_native"] == out["leaf_count_reference"] > 0
    assert out["time_native_s"] > 0 and out["time_reference_s"] > 0


@pytest.mark.realdata
def test_agreement_on_real_scan_at_10_cells_per_metre():
    """Both backends agree on a real LiDAR scan's long, crossing rays at 0.1 m.

    Every 8th point of the scan (11k rays over its whole extent, the same flat grid
    path) is enough: with occupied ends left free in the native grid the Jaccard drops
    to 0.55, and the reference backend's per-point cost is an eighth of the whole scan's.
    """
    path = REALDATA / "scan.dat.bz2"
    if not path.exists():
        pytest.skip("../shared/realdata/octomap_scan/scan.dat.bz2 absent")
    with bz2.open(path) as handle:  # whitespace-separated x y z rows
        points = np.fromstring(handle.read().decode(), sep=" ").reshape(-1, 3)
    assert points.shape == (88206, 3)
    out = compare_backends([(points[::8], np.zeros(3))], resolution=10)
    assert out["jaccard"] == 1.0
    assert out["leaf_count_native"] == out["leaf_count_reference"] > 0


@pytest.mark.parametrize("backend", BACKENDS)
def test_single_ray_marks_free_voxels_and_occupied_end(backend):
    mapper = Octomap(resolution=10, backend=backend)
    mapper.insert(np.array([[2.05, 0.05, 0.05]]), np.array([0.05, 0.05, 0.05]))
    cells = mapper.cells()
    assert len(cells) == 21
    occupied = cells.centers[cells.occupied]
    np.testing.assert_allclose(occupied, [[2.05, 0.05, 0.05]], atol=1e-9)
    free = np.sort(cells.centers[~cells.occupied][:, 0])
    np.testing.assert_allclose(free, 0.05 + 0.1 * np.arange(20), atol=1e-9)
    np.testing.assert_allclose(cells.value[~cells.occupied], 0.4, atol=1e-6)
    np.testing.assert_allclose(cells.value[cells.occupied], 0.7, atol=1e-6)


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize(("model", "clamp"), [("matlab", 0.999), ("octomap", 0.971)])
def test_repeated_hits_saturate_at_the_clamp(backend, model, clamp):
    mapper = Octomap(resolution=5, backend=backend, sensor_model=model)
    for _ in range(30):
        mapper.insert(np.array([[1.1, 0.1, 0.1]]), np.zeros(3))
    leaves = mapper.leaves()
    assert leaves.value.max() == logodds(clamp)
    assert leaves.value.min() < 0  # the ray's free voxels


@pytest.mark.parametrize("backend", BACKENDS)
def test_max_range_truncates_ray_and_drops_its_end(backend):
    mapper = Octomap(resolution=10, max_range=1.0, backend=backend)
    mapper.insert(np.array([[5.05, 0.05, 0.05]]), np.array([0.05, 0.05, 0.05]))
    cells = mapper.cells()
    assert not cells.occupied.any()
    assert cells.centers[:, 0].max() < 1.1
    assert len(cells) == 10


def test_incremental_equals_build_with_per_point_origins():
    incremental = Octomap(resolution=5)
    for points, origin in SCANS:
        incremental.insert(points, origin)
    batch = Octomap(resolution=5)
    cloud = np.vstack([p for p, _ in SCANS])
    origins = np.vstack([np.broadcast_to(o, p.shape) for p, o in SCANS])
    batch.build(cloud, origins)
    assert _leaf_set(incremental) == _leaf_set(batch)


def test_build_without_origins_marks_point_voxels_only():
    mapper = Octomap(resolution=2)
    mapper.build(np.array([[0.1, 0.1, 0.1], [0.2, 0.2, 0.2], [3.1, 0.1, 0.1]]))
    cells = mapper.cells()
    assert len(cells) == 2 and cells.occupied.all()


@settings(max_examples=15, deadline=None)
@given(st.randoms(use_true_random=False))
def test_point_order_within_a_scan_does_not_matter(rnd):
    points, origin = SCANS[0]
    order = np.arange(points.shape[0])
    rnd.shuffle(order)
    first, second = Octomap(resolution=5), Octomap(resolution=5)
    first.insert(points, origin)
    second.insert(points[order], origin)
    assert _leaf_set(first) == _leaf_set(second)


def test_leaves_partition_without_overlap_and_respect_resolution():
    mapper = Octomap(resolution=5)
    for points, origin in SCANS:
        mapper.insert(points, origin)
    leaves, cells = mapper.leaves(), mapper.cells()
    span = 8 ** (16 - leaves.depth)
    first = leaves.prefix * span.astype(np.uint64)
    order = np.argsort(first)
    ends = first[order] + span[order].astype(np.uint64)
    assert (first[order][1:] >= ends[:-1]).all()  # Morton ranges are disjoint
    np.testing.assert_allclose(cells.sizes[:, 0], 0.2 * 2.0 ** (16 - cells.level))
    assert cells.sizes.min() == pytest.approx(0.2)
    store = mapper._tree.store
    assert store.blocks == np.unique(mapper._tree.keys >> np.uint64(9)).size
    assert mapper.memory_bytes == store.blocks * 2056 + 16 * store._slots.size


def test_prune_collapses_identical_siblings_recursively():
    keys = np.sort(morton_encode(np.array(
        [[x, y, z] for x in range(4) for y in range(4) for z in range(4)], dtype=np.int64)))
    same = prune(Leaves(keys, np.full(64, 16), np.full(64, 0.5, np.float32)))
    assert same.depth.tolist() == [14]
    values = np.full(64, 0.5, np.float32)
    values[0] = 0.25
    mixed = prune(Leaves(keys, np.full(64, 16), values))
    assert sorted(mixed.depth.tolist()) == [15] * 7 + [16] * 8


def test_pruning_voxels_directly_equals_the_general_prune():
    """The store's fast path (sorted depth-16 voxels) gives the general prune's leaves."""
    rng = np.random.default_rng(5)
    cube = np.array([[x, y, z] for x in range(16) for y in range(16) for z in range(16)])
    keys = np.unique(morton_encode(np.concatenate([cube + 64, rng.integers(0, 200, (3000, 3))])
                                   .astype(np.int64)))
    values = np.where(rng.random(keys.size) < 0.2, 0.85, -0.4).astype(np.float32)
    values[keys < morton_encode(np.array([[80, 80, 80]]))[0]] = -0.4  # whole blocks agree
    fast = prune_voxels(keys, values)
    general = prune(Leaves(keys, np.full(keys.size, 16), values))
    assert fast.depth.min() < 15  # collapses over several depths happened
    for field in ("prefix", "depth", "value"):
        np.testing.assert_array_equal(getattr(fast, field), getattr(general, field))


def test_corners_of_one_occupied_voxel():
    mapper = Octomap(resolution=2)
    mapper.build(np.array([[0.1, 0.1, 0.1]]))
    corners = mapper.corners()
    assert corners.shape == (8, 3)
    np.testing.assert_allclose(np.unique(corners), [0.0, 0.5])


def test_write_bt_is_byte_identical_to_reference_and_reads_back(tmp_path):
    native, reference = Octomap(resolution=5), Octomap(resolution=5, backend="reference")
    for points, origin in SCANS:
        native.insert(points, origin)
        reference.insert(points, origin)
    a = native.write_bt(tmp_path / "native.bt")
    b = reference.write_bt(tmp_path / "reference.bt")
    assert a.read_bytes() == b.read_bytes()
    cells = read_bt(a)
    occupied = cells.centers[cells.occupied]
    assert len(cells) > 0 and occupied.shape[0] > 0
    with pytest.raises(AlteError, match="already exists"):
        native.write_bt(a)
    assert reference.basis_functions == native.basis_functions  # writing did not alter it


@pytest.mark.realdata
def test_read_bt_of_the_fr079_map():
    path = REALDATA / "geb079.bt"
    if not path.exists():
        pytest.skip("../shared/realdata/octomap_scan/geb079.bt absent")
    cells = read_bt(path)
    assert len(cells) == 428144
    assert cells.sizes.min() == pytest.approx(0.08)
    assert 0 < cells.occupied.sum() < len(cells)


def test_read_bt_errors(tmp_path):
    with pytest.raises(MapperError, match="does not exist"):
        read_bt(tmp_path / "missing.bt")
    bad = tmp_path / "bad.bt"
    bad.write_text("not an octree\n")
    with pytest.raises(MapperError, match="not a readable OctoMap"):
        read_bt(bad)


@pytest.mark.parametrize(("params", "match"), [
    ({"resolution": 0}, "resolution"),
    ({"resolution": -1}, "resolution"),
    ({"prob_hit": 1.0}, "prob_hit"),
    ({"prob_hit": 0.4}, "prob_hit"),
    ({"prob_miss": 0.0}, "prob_miss"),
    ({"clamp_min": 0.6}, "clamp_min"),
    ({"clamp_max": 1.5}, "clamp_max"),
    ({"occupancy_threshold": 1.0}, "occupancy_threshold"),
    ({"clamp_min": 0.45, "occupancy_threshold": 0.4}, "clamp_min must be below"),
    ({"clamp_max": 0.6, "occupancy_threshold": 0.65}, "clamp_max must be above"),
    ({"max_range": 0}, "max_range"),
    ({"backend": "gpu"}, "backend"),
    ({"sensor_model": "velodyne"}, "sensor_model"),
    ({"voxel": 1}, "unknown parameter"),
    ({"resolution": "fine"}, "resolution"),
])
def test_bad_parameters_raise(params, match):
    with pytest.raises(ParameterError, match=match):
        Octomap(**params)


def test_string_parameters_are_accepted():
    mapper = Octomap(resolution="10", max_range="-1", sensor_model="octomap")
    assert mapper.params.resolution == 10.0 and mapper.params.clamp_max == 0.971


@pytest.mark.parametrize(("points", "origin", "match"), [
    (np.zeros((4, 2)), np.zeros(3), "points must have shape"),
    (np.array([[0.0, np.nan, 0.0]]), np.zeros(3), "NaN"),
    (np.zeros((4, 3)), np.array([0.0, np.inf, 0.0]), "origin contains"),
    (np.zeros((4, 3)), np.zeros(2), "origin must have shape"),
])
def test_bad_arrays_raise(points, origin, match):
    with pytest.raises(MapperError, match=match):
        Octomap().insert(points, origin)


def test_build_rejects_mismatched_origins():
    with pytest.raises(MapperError, match="origins must be"):
        Octomap().build(np.zeros((4, 3)), np.zeros((3, 3)))


def _one_array_update(keys, values, new_keys, updates, clamp):
    """The plain single-sorted-array update that VoxelStore must reproduce bit for bit."""
    pos = np.searchsorted(keys, new_keys)
    found = pos < keys.size
    found[found] = keys[pos[found]] == new_keys[found]
    values[pos[found]] = np.clip(values[pos[found]] + updates[found], *clamp)
    fresh = np.clip(np.float32(0) + updates[~found], *clamp).astype(np.float32)
    return np.insert(keys, pos[~found], new_keys[~found]), np.insert(values, pos[~found], fresh)


def _store_update(store, keys, updates, clamp):
    """Feed ``keys`` with their miss (< 0) or hit (> 0) updates to a VoxelStore."""
    for word0, mask in ((0, updates < 0), (WORDS, updates > 0)):
        blocks, bits = keys_to_blocks(keys[mask], word0)
        store.update(blocks, bits, logodds(0.4), logodds(0.7), clamp)


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 2**31), st.integers(1, 40))
def test_voxel_store_equals_one_sorted_array(seed, batches):
    rng = np.random.default_rng(seed)
    clamp = (logodds(0.12), logodds(0.97))
    store, keys, values = VoxelStore(), np.empty(0, np.uint64), np.empty(0, np.float32)
    for _ in range(batches):  # overlapping batches of mixed hits/misses, some clamping,
        # spread over more blocks than a page holds
        batch = np.unique(rng.integers(0, 2**20, rng.integers(1, 3000)).astype(np.uint64))
        updates = np.where(rng.random(batch.size) < 0.5, logodds(0.7), logodds(0.4))
        _store_update(store, batch, updates, clamp)
        keys, values = _one_array_update(keys, values, batch, updates.astype(np.float32), clamp)
        assert len(store) == keys.size
    folded_keys, folded_values = store.fold()
    np.testing.assert_array_equal(folded_keys, keys)
    assert folded_values.dtype == np.float32
    assert folded_values.tobytes() == values.tobytes()
    assert store.blocks == np.unique(keys >> np.uint64(9)).size


def test_voxel_store_grows_by_pages_and_refolds_after_an_update():
    store = VoxelStore()
    clamp = (logodds(0.12), logodds(0.97))
    assert store.fold()[0].size == 0 and store.blocks == 0
    for start in range(0, 3 * PAGE * 512, 4096):  # brand-new blocks on every batch
        batch = np.arange(start, start + 4096, 64, dtype=np.uint64)
        _store_update(store, batch, np.full(batch.size, logodds(0.7)), clamp)
    assert store.blocks == 3 * PAGE and len(store._pages) == 3
    assert store.fold()[0].size == 3 * PAGE * 8
    _store_update(store, np.array([1], np.uint64), np.array([logodds(0.4)]), clamp)
    keys, values = store.fold()
    assert keys.size == 3 * PAGE * 8 + 1 and keys[1] == 1 and values[1] == logodds(0.4)
