"""Property-based tests across ALL mappers (via ``make_mapper``), registration and metrics.

Mapper-specific properties live beside each mapper (tests/mappers); here the same
properties are asserted for every registered mapper through the public factory:
the leaves partition the domain, counts are conserved, inserting frame by frame
equals one batch build, and the order of the points does not matter. Coordinates
are multiples of 1/8 m so sums are exact and maps can be compared bit for bit.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from scipy.spatial.transform import Rotation

from alte.io.bags.bag import read_frames
from alte.io.bags.writer import write_frames
from alte.mappers import Domain, make_mapper, registry
from alte.metrics.hausdorff import hausdorff
from alte.registration import register, to_sensor
from alte.types import Frame, Mount

#: Small fixed-domain settings (16 m square / cube at 0) so incremental == batch exactly.
CUBE = Domain(0.0, 0.0, 0.0, 16.0)
PARAMS = {
    "quadtree": {"max_points": 3, "max_depth": 5, "domain": CUBE},
    "alte2d": {"kappa": 0.05, "max_res": 5, "min_pts": 2, "domain": CUBE},
    "alte3d": {"max_res": 4, "min_pts": 2, "min_pts_split": 3, "domain": CUBE},
    "octomap": {"resolution": 2.0, "max_range": -1.0},
}
ORIGIN = np.array([8.0, 8.0, 15.0])

eighths = st.integers(0, 127).map(lambda v: v / 8.0)  # [0, 16) on an exact binary grid
clouds = arrays(np.float64, st.tuples(st.integers(1, 60), st.just(3)), elements=eighths)
cuts = st.lists(st.integers(0, 60), max_size=4)

#: The thesis' four by name.
BUILTIN = {cls.name: cls for cls in registry.BUILTIN}


def _cells(mapper) -> dict[str, np.ndarray]:
    return mapper.cells().as_dict()


def _assert_same(a: dict[str, np.ndarray], b: dict[str, np.ndarray]) -> None:
    """Same leaves and flags; means may differ in the last bits (merge order of the sums)."""
    for name, value in a.items():
        if name in {"centers", "value"}:
            np.testing.assert_allclose(value, b[name], rtol=1e-12, atol=1e-12, equal_nan=True,
                                       err_msg=name)
        else:
            np.testing.assert_array_equal(value, b[name], err_msg=name)


def _frames(points: np.ndarray, cut: list[int]) -> list[np.ndarray]:
    return np.split(points, sorted({min(c, len(points)) for c in cut}))


def test_every_registered_mapper_is_covered():
    assert set(PARAMS) == set(BUILTIN)


@pytest.mark.parametrize("name", sorted(PARAMS))
@settings(max_examples=25, deadline=None)
@given(points=clouds, cut=cuts)
def test_incremental_equals_batch(name, points, cut):
    """Frames inserted one by one == ``build`` with one origin per point (a run = a scan)."""
    frames = [f for f in _frames(points, cut) if len(f)]
    origins = [ORIGIN + np.array([0.0, 0.0, 0.5 * k]) for k in range(len(frames))]
    one_by_one = make_mapper(name, **PARAMS[name])
    for part, origin in zip(frames, origins, strict=True):
        one_by_one.insert(part, origin)
    batch = make_mapper(name, **PARAMS[name])
    batch.build(np.vstack(frames), np.repeat(origins, [len(f) for f in frames], axis=0))
    _assert_same(_cells(one_by_one), _cells(batch))
    assert one_by_one.basis_functions == batch.basis_functions


@pytest.mark.parametrize("name", sorted(PARAMS))
@settings(max_examples=25, deadline=None)
@given(points=clouds, seed=st.integers(0, 2**16))
def test_point_order_does_not_matter(name, points, seed):
    shuffled = points[np.random.default_rng(seed).permutation(len(points))]
    maps = []
    for cloud in (points, shuffled):
        mapper = make_mapper(name, **PARAMS[name])
        mapper.insert(cloud, ORIGIN)
        maps.append(_cells(mapper))
    _assert_same(*maps)


@pytest.mark.parametrize("name", ["quadtree", "alte2d", "alte3d"])
@settings(max_examples=25, deadline=None)
@given(points=clouds)
def test_leaves_partition_the_domain_and_hold_every_point(name, points):
    mapper = make_mapper(name, **PARAMS[name])
    mapper.build(points, ORIGIN)
    cells = mapper.cells()
    dims = mapper.dims
    lo = cells.centers[:, :dims] - cells.sizes[:, :dims] / 2
    hi = lo + cells.sizes[:, :dims]
    assert np.prod(cells.sizes[:, :dims], axis=1).sum() == pytest.approx(16.0**dims)
    inside = np.all((points[:, None, :dims] >= lo) & (points[:, None, :dims] <= hi), axis=2)
    assert inside.any(axis=1).all()  # every point lies in a leaf (closed cells)
    strict = np.all((points[:, None, :dims] >= lo) & (points[:, None, :dims] < hi), axis=2)
    interior = np.all(points[:, :dims] < 16.0, axis=1)
    assert (strict.sum(axis=1)[interior] == 1).all()  # half-open leaves never overlap
    if name == "alte3d":
        assert cells.value.sum() == len(points)  # value = point count per leaf


@settings(max_examples=25, deadline=None)
@given(points=clouds)
def test_octomap_leaves_are_disjoint(points):
    mapper = make_mapper("octomap", **PARAMS["octomap"])
    mapper.insert(points, ORIGIN)
    keys = mapper.occupied_voxels()
    assert np.array_equal(keys, np.unique(keys))
    cells = mapper.cells()
    assert (cells.sizes > 0).all() and len(cells) == mapper.basis_functions


# ------------------------------------------------------------------ registration through a bag


unit = st.floats(-1.0, 1.0, allow_nan=False)


@settings(max_examples=8, deadline=None)
@given(
    quats=arrays(np.float64, (3, 4), elements=unit).filter(
        lambda q: (np.linalg.norm(q, axis=1) > 0.2).all()),
    offset=st.sampled_from([0.0, 5.0e5, 5.4e6]),
    seed=st.integers(0, 2**16),
)
def test_registered_bag_maps_back_to_the_sensor_points(tmp_path_factory, quats, offset, seed):
    """Bag (float64 clouds) -> read_frames -> register -> to_sensor gives back every point."""
    rng = np.random.default_rng(seed)
    mount = Mount(rng.uniform(-0.2, 0.2, 3), Rotation.random(random_state=seed).as_quat())
    frames = [Frame(10**10 + k * 10**8, rng.uniform(-30, 30, (20, 3)),
                    offset + rng.uniform(-50, 50, 3), q / np.linalg.norm(q))
              for k, q in enumerate(quats)]
    bag = write_frames(tmp_path_factory.mktemp("bag") / "b", frames, mount, dtype=np.float64)
    frameset = read_frames(bag)
    result = register(frameset.frames, frameset.mount)
    parts = np.split(result.points, np.cumsum(result.frame_points)[:-1])
    tol = 1e-9 * max(1.0, offset)
    for frame, part in zip(frames, parts, strict=True):
        np.testing.assert_allclose(to_sensor(part, frame, mount), frame.points, atol=tol)


# ------------------------------------------------------------------ metrics


sets = arrays(np.float64, st.tuples(st.integers(1, 40), st.just(3)),
              elements=st.floats(-50, 50, allow_nan=False))


@settings(max_examples=60, deadline=None)
@given(a=sets, b=sets)
def test_hausdorff_order_symmetry_and_identity(a, b):
    ab, ba = hausdorff(a, b), hausdorff(b, a)
    assert ab.hd >= ab.mhd >= 0.0
    assert (ab.hd, ab.mhd) == (ba.hd, ba.mhd)
    assert (ab.h_ab, ab.mh_ab) == (ba.h_ba, ba.mh_ba)
    same = hausdorff(a, a[::-1])
    assert same.hd == same.mhd == 0.0
