"""Tests for alte.registration: eq. 2.2, grid average, box-grid merge, crop, manoeuvre filter."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation
from support.synthetic import make_frame, scene

from alte.errors import ParameterError, RegistrationError
from alte.registration import (
    GridAccumulator,
    ManoeuvreFilter,
    RegistrationCounts,
    box_grid_merge,
    check_options,
    crop,
    crop_mask,
    grid_average,
    grid_average_with_counts,
    register,
    register_frame,
    register_frames,
    sensor_origin,
    to_sensor,
)
from alte.types import Frame, Mount, thesis_mount


def test_register_frame_reproduces_known_inertial_cloud():
    truth, frames, mount = scene()
    for inertial, frame in zip(truth, frames, strict=True):
        np.testing.assert_allclose(register_frame(frame, mount), inertial, rtol=0, atol=1e-9)


def test_register_frame_hand_case():
    yaw90 = Rotation.from_euler("z", 90, degrees=True).as_quat()
    mount = Mount(np.array([0.1, 0.0, 0.0]))
    frame = make_frame([[1.0, 0.0, 0.0]], position=(1, 2, 3), quat=yaw90)
    np.testing.assert_allclose(register_frame(frame, mount), [[1.0, 3.1, 3.0]], atol=1e-12)
    np.testing.assert_allclose(sensor_origin(frame, mount), [1.0, 2.1, 3.0], atol=1e-12)


def test_registered_cloud_of_two_hand_posed_frames() -> None:
    """Two frames with poses written by hand, merged on a 1 m grid: every expected point
    is worked out on paper (a 90 degree yaw sends sensor (x, y) to world (-y, x))."""
    yaw90 = Rotation.from_euler("z", 90, degrees=True).as_quat()
    still = make_frame([[0.2, 0.2, 0.2], [0.4, 0.4, 0.4]])
    turned = make_frame([[0.2, -0.5, 0.3],    # -> (5.5, 0.2, 0.3)
                         [0.4, -0.7, 0.1],    # -> (5.7, 0.4, 0.1)
                         [0.6, 4.7, 0.5]],    # -> (0.3, 0.6, 0.5), in the first cell
                        position=(5.0, 0.0, 0.0), quat=yaw90, stamp=1)
    reg = register([still, turned], Mount(np.zeros(3)), voxel=1.0)
    # cell (0, 0, 0): the mean of its three points; cell (5, 0, 0): of its two
    np.testing.assert_allclose(reg.points, [[0.3, 0.4, 1.1 / 3], [5.6, 0.3, 0.2]],
                               atol=1e-12)
    np.testing.assert_allclose(np.asarray(reg.origins), [[0.0, 0.0, 0.0], [5.0, 0.0, 0.0]],
                               atol=1e-12)
    raw = register([still, turned], Mount(np.array([0.0, 0.0, -0.5])))  # sensor 0.5 m below
    np.testing.assert_allclose(raw.points, [[0.2, 0.2, -0.3], [0.4, 0.4, -0.1],
                                            [5.5, 0.2, -0.2], [5.7, 0.4, -0.4],
                                            [0.3, 0.6, 0.0]], atol=1e-12)


def test_thesis_mount_looks_forward_and_30_deg_down():
    frame = make_frame([[0.0, 1.0, 0.0]])
    mount = thesis_mount()
    direction = register_frame(frame, mount)[0] - sensor_origin(frame, mount)
    np.testing.assert_allclose(direction, [np.cos(np.radians(30)), 0, -0.5], atol=1e-12)


finite = st.floats(-100, 100, allow_nan=False)


@settings(max_examples=40, deadline=None)
@given(
    quat=st.lists(st.floats(-1, 1), min_size=4, max_size=4).filter(
        lambda q: np.linalg.norm(q) > 0.1
    ),
    mquat=st.lists(st.floats(-1, 1), min_size=4, max_size=4).filter(
        lambda q: np.linalg.norm(q) > 0.1
    ),
    position=st.lists(finite, min_size=3, max_size=3),
    offset=st.lists(st.floats(-1, 1), min_size=3, max_size=3),
    points=st.lists(st.lists(finite, min_size=3, max_size=3), min_size=1, max_size=20),
)
def test_to_sensor_inverts_register_frame(quat, mquat, position, offset, points):
    mount = Mount(np.array(offset), np.array(mquat))
    frame = make_frame(points, position, np.array(quat) / np.linalg.norm(quat))
    back = to_sensor(register_frame(frame, mount), frame, mount)
    np.testing.assert_allclose(back, frame.points, rtol=0, atol=1e-9)


def test_grid_average_hand_case_boundaries_and_negatives():
    pts = np.array([
        [0.5, 0.5, 0.5], [0.7, 0.1, 0.2],  # cell (0, 0, 0)
        [1.0, 0.0, 0.0],  # on the boundary: cell (1, 0, 0)
        [-0.5, 0.0, 0.0], [-1.0, 0.0, 0.0],  # cell (-1, 0, 0); -1.0 is its lower edge
    ])
    out = grid_average(pts, 1.0)
    np.testing.assert_allclose(out, [[-0.75, 0, 0], [0.6, 0.3, 0.35], [1.0, 0, 0]])
    keys, sums, counts = grid_average_with_counts(pts, 1.0)
    np.testing.assert_array_equal(keys, [[-1, 0, 0], [0, 0, 0], [1, 0, 0]])
    np.testing.assert_array_equal(counts, [2, 2, 1])
    np.testing.assert_allclose(sums[1], [1.2, 0.6, 0.7])


def test_grid_average_sorted_by_key_and_empty():
    pts = np.array([[0.1, 5.2, 0], [0.2, -3.0, 0], [-0.1, 9.0, 0]])
    np.testing.assert_allclose(grid_average(pts, 1.0), pts[[2, 1, 0]])
    assert grid_average(np.empty((0, 3)), 0.5).shape == (0, 3)


@pytest.mark.parametrize("voxel", [0.0, -1.0, np.nan, np.inf])
def test_grid_average_rejects_bad_voxel(voxel):
    with pytest.raises(ParameterError, match="voxel"):
        grid_average(np.zeros((2, 3)), voxel)


def test_box_grid_merge_hand_case():
    merged = box_grid_merge([[0.2, 0.2, 0.2]], [[0.4, 0.4, 0.4], [2.5, 0.0, -0.5]], 1.0)
    np.testing.assert_allclose(merged, [[0.3, 0.3, 0.3], [2.5, 0.0, -0.5]])


def test_accumulator_equals_grid_average_of_everything_in_any_order():
    rng = np.random.default_rng(3)
    chunks = [rng.uniform(-50, 50, (3000, 3)) for _ in range(8)]  # > 4096 cells: folds
    expected = grid_average(np.vstack(chunks), 0.5)
    for order in (range(8), reversed(range(8))):
        acc = GridAccumulator(0.5)
        for i in order:
            acc.add(chunks[i])
        np.testing.assert_allclose(acc.points(), expected, rtol=0, atol=1e-12)
        assert acc.counts().sum() == 8 * 3000


def test_accumulator_weights_cell_means_by_their_points():
    acc = GridAccumulator(1.0)
    assert acc.add(np.array([[0.1, 0, 0]]), weights=np.array([3.0])) == 1
    acc.add(np.array([[0.5, 0, 0]]))
    np.testing.assert_allclose(acc.points(), [[0.2, 0, 0]])


def test_crop_inclusive_bounds():
    pts = np.array([[0, 0, 0], [1, 1, 1], [1.0001, 0, 0], [-1, -1, -1], [0.5, 0.5, -1.01]])
    box = (-1, -1, -1, 1, 1, 1)
    np.testing.assert_array_equal(crop_mask(pts, box), [True, True, False, True, False])
    np.testing.assert_array_equal(crop(pts, box), pts[[0, 1, 3]])


@pytest.mark.parametrize("box", [(0, 0, 0, 1, 1), (1, 0, 0, 0, 1, 1), (0, 0, 0, np.nan, 1, 1)])
def test_crop_rejects_bad_box(box):
    with pytest.raises(ParameterError, match="crop box"):
        crop(np.zeros((1, 3)), box)


def test_manoeuvre_filter_counts_reasons():
    gate = ManoeuvreFilter(max_rate_rad_s=1.0, max_offset_s=0.1)
    frames = [
        make_frame([[0, 0, 0]], rate=r, offset=o)
        for r, o in [(0.1, 0), (2.0, 0), (0.1, 0.5), (3.0, 0.5), (-0.5, -0.05), (np.nan, 0)]
    ]
    kept = [gate.keep(f) for f in frames]
    assert kept == [True, False, False, False, True, False]
    assert gate.dropped == {"rate": 3, "offset": 1}
    assert ManoeuvreFilter().keep(frames[3])


@pytest.mark.parametrize(("kwargs", "name"), [
    ({"max_rate_rad_s": 0.0}, "max_rate_rad_s"),
    ({"max_offset_s": -1.0}, "max_offset_s"),
    ({"max_offset_s": np.inf}, "max_offset_s"),
])
def test_manoeuvre_filter_rejects_bad_limits(kwargs, name):
    with pytest.raises(ParameterError, match=name):
        ManoeuvreFilter(**kwargs)


def test_register_merges_counts_and_matches_grid_average():
    truth, frames, mount = scene(seed=5, frames=5, n=300)
    slow = make_frame(frames[0].points, frames[0].position, frames[0].quaternion, rate=5.0)
    late = make_frame(frames[0].points, frames[0].position, frames[0].quaternion, offset=1.0)
    empty = make_frame(np.empty((0, 3)))
    nan_frame = make_frame(np.r_[frames[1].points[:10], [[np.nan, 0, 0]]],
                           frames[1].position, frames[1].quaternion)
    stream = [*frames, slow, late, empty, nan_frame]
    box = (-4, -4, -4, 4, 4, 4)
    reg = register(stream, mount, voxel=0.5, crop_box=box, max_rate=1.0, max_offset=0.1)
    cropped = [crop(t, box) for t in [*truth, truth[1][:10]]]
    np.testing.assert_allclose(reg.points, grid_average(np.vstack(cropped), 0.5), atol=1e-9)
    c = reg.counts
    assert (c.frames_in, c.frames_kept) == (9, 6)
    assert (c.frames_dropped_rate, c.frames_dropped_offset, c.frames_dropped_empty) == (
        1, 1, 1)
    assert c.points_in == 5 * 300 + 11
    assert c.points_dropped_nonfinite == 1
    assert c.points_dropped_crop == 5 * 300 + 10 - sum(len(p) for p in cropped)
    assert c.points_out == len(reg.points)
    sizes = [len(grid_average(p, 0.5)) for p in cropped]
    np.testing.assert_array_equal(reg.frame_points, sizes)
    assert c.points_registered == sum(sizes)
    np.testing.assert_allclose(reg.origins[0], sensor_origin(frames[0], mount))
    np.testing.assert_array_equal(reg.stamps, [f.stamp for f in [*frames, nan_frame]])


def test_register_without_voxel_concatenates():
    truth, frames, mount = scene(seed=2, frames=3, n=50)
    reg = register(iter(frames), mount)
    np.testing.assert_allclose(reg.points, np.vstack(truth), atol=1e-9)
    assert reg.counts.points_out == 150
    np.testing.assert_array_equal(reg.frame_points, [50, 50, 50])


def test_register_frames_yields_per_kept_frame():
    truth, frames, mount = scene(seed=4, frames=3, n=40)
    counts = RegistrationCounts()
    out = list(register_frames(frames, mount, voxel=1.0, counts=counts))
    assert len(out) == 3
    for (frame, pts, origin), inertial in zip(out, truth, strict=True):
        np.testing.assert_allclose(pts, grid_average(inertial, 1.0), atol=1e-9)
        np.testing.assert_allclose(origin, sensor_origin(frame, mount))
    assert counts.frames_kept == 3
    assert counts.points_registered == sum(len(p) for _f, p, _o in out)


@pytest.mark.parametrize("merge_voxel", [1.0, 0.7])
def test_frames_down_sampled_and_merged_on_one_grid_equal_each_done_alone(merge_voxel):
    """The pipeline down-samples each frame and merges it into the cloud; on one grid the
    frame's points are grouped once for both, with the same frames and cloud as grouping
    them twice (and on another grid, each as before)."""
    _truth, frames, mount = scene(seed=5, frames=4, n=300)
    merge = GridAccumulator(merge_voxel)
    out = list(register_frames(frames, mount, voxel=1.0, merge=merge))
    alone = GridAccumulator(merge_voxel)
    for (_f, pts, _o), (_g, raw, _p) in zip(out, register_frames(frames, mount), strict=True):
        assert np.array_equal(pts, grid_average(raw, 1.0))
        alone.add(raw)
    assert np.array_equal(merge.points(), alone.points())
    assert np.array_equal(merge.counts(), alone.counts())


def test_register_errors_name_the_reason():
    with pytest.raises(RegistrationError, match="no frames to register"):
        register([], Mount())
    frames = [make_frame([[0, 0, 0]], rate=3.0), make_frame([[9, 9, 9]])]
    with pytest.raises(RegistrationError, match=r"all 2 frames dropped \(1 rate, 1 empty\)"):
        register(frames, Mount(), max_rate=1.0, crop_box=(-1, -1, -1, 1, 1, 1))
    bad = Frame(stamp=7, points=np.zeros((2, 2)), position=np.zeros(3),
                quaternion=np.array([0, 0, 0, 1.0]))
    with pytest.raises(RegistrationError, match="stamp 7"):
        register([bad], Mount())


def test_options_are_checked_before_any_frame_is_read():
    def exploding():
        raise AssertionError("frames were read")
        yield  # pragma: no cover

    with pytest.raises(ParameterError, match="voxel"):
        register_frames(exploding(), Mount(), voxel=-1)
    with pytest.raises(ParameterError, match="crop box"):
        register_frames(exploding(), Mount(), crop_box=(0, 0))
    with pytest.raises(ParameterError, match="max_rate"):
        check_options(max_rate=-2)


def test_grid_average_rejects_mismatched_weights():
    with pytest.raises(ParameterError, match=r"weights have shape \(2,\), expected \(3,\)"):
        grid_average_with_counts(np.zeros((3, 3)), 1.0, weights=np.ones(2))


def test_grid_average_huge_key_span_falls_back_to_lexsort():
    pts = np.array([[4e18, 0, 0], [-4e18, 1, 0], [4e18, 1.5, 0], [-4e18, -3, 2]])
    out = grid_average(pts, 1.0)
    np.testing.assert_allclose(out, [[-4e18, -3, 2], [-4e18, 1, 0], [4e18, 0, 0], [4e18, 1.5, 0]])


def test_grid_average_order_matches_lexsort_of_cell_keys():
    pts = np.random.default_rng(9).uniform(-30, 30, (2000, 3))
    keys, _sums, _counts = grid_average_with_counts(pts, 0.7)
    np.testing.assert_array_equal(keys, np.unique(np.floor(pts / 0.7).astype(np.int64), axis=0))


@pytest.mark.parametrize("scale", [1.0, 1e12, 1e15])  # row in the key; code alone; lexsort
def test_cell_order_is_the_stable_lexicographic_order(scale):
    from alte.registration.grid import _sort_keys

    rng = np.random.default_rng(4)
    keys = (rng.integers(-40, 40, (20_000, 3)) * np.array([1, 1, int(scale)])).astype(np.int64)
    order, starts = _sort_keys(keys)
    want = np.lexsort((keys[:, 2], keys[:, 1], keys[:, 0]))  # stable: ties in row order
    assert np.array_equal(order, want)
    ordered = keys[want]
    assert np.array_equal(starts, np.flatnonzero(np.r_[True, np.any(ordered[1:] != ordered[:-1],
                                                                      axis=1)]))
