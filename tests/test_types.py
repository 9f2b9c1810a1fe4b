import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from alte.errors import PoseError
from alte.types import Frame, Mount, as_points, finite_rows, rows_all, thesis_mount


def _frame(**kw):
    base = dict(stamp=1_500_000_000, points=np.zeros((2, 3)), position=np.zeros(3),
                quaternion=np.array([0.0, 0.0, 0.0, 1.0]))
    base.update(kw)
    return Frame(**base)


def test_frame_time_and_rotation():
    frame = _frame(quaternion=Rotation.from_euler("z", 90, degrees=True).as_quat())
    assert frame.time == pytest.approx(1.5)
    np.testing.assert_allclose(frame.rotation.apply([1.0, 0, 0]), [0, 1, 0], atol=1e-12)


def test_frame_equality_compares_arrays():
    assert _frame() == _frame()
    assert _frame() != _frame(points=np.ones((2, 3)))
    assert _frame() != _frame(stamp=1)


def test_as_points_shape_error():
    with pytest.raises(ValueError, match=r"cloud must have shape \(N, 3\)"):
        as_points(np.zeros((4, 2)), "cloud")


def test_mount_normalizes_quaternion():
    mount = Mount(np.zeros(3), np.array([0.0, 0.0, 0.0, 2.0]))
    np.testing.assert_allclose(mount.quaternion, [0, 0, 0, 1])


def test_mount_rejects_zero_quaternion():
    with pytest.raises(PoseError, match="zero norm"):
        Mount(np.zeros(3), np.zeros(4))


def test_mount_rejects_bad_shapes():
    with pytest.raises(PoseError, match="3 offsets and 4 quaternion"):
        Mount(np.zeros(2), np.array([0.0, 0, 0, 1]))


def test_mount_string_round_trip():
    mount = Mount.from_string("0.1,0,-0.08,0,30,-90")
    again = Mount.from_string(mount.to_string())
    np.testing.assert_allclose(again.translation, mount.translation)
    assert (again.rotation.inv() * mount.rotation).magnitude() < 1e-9


@pytest.mark.parametrize("text", ["1,2,3", "a,b,c,d,e,f", ""])
def test_mount_string_errors(text):
    with pytest.raises(PoseError, match="expected 6 numbers"):
        Mount.from_string(text)


def test_thesis_mount_looks_forward_30_deg_down():
    look = thesis_mount().rotation.apply([0.0, 1.0, 0.0])  # sensor +y: centre of the FoV
    np.testing.assert_allclose(look, [np.cos(np.radians(30)), 0, -np.sin(np.radians(30))],
                               atol=1e-12)


def test_rows_all_and_finite_rows_match_numpy() -> None:
    rng = np.random.default_rng(3)
    pts = rng.normal(size=(500, 3))
    assert finite_rows(pts) is None
    pts[[3, 70, 71], [0, 2, 1]] = [np.nan, np.inf, -np.inf]
    assert np.array_equal(finite_rows(pts), np.isfinite(pts).all(axis=1))
    mask = rng.random((200, 4)) > 0.2
    assert np.array_equal(rows_all(mask), mask.all(axis=1))


def test_every_counter_gives_its_counts_by_name_as_copies() -> None:
    """The four counters share ``Counts.as_dict``: every field by name, lists and dicts
    copied so that a summary does not change when the run goes on counting."""
    from alte.io.bags.bag import ReadCounts
    from alte.registration.deskew import DeskewCounts
    from alte.registration.odometry import PoseCounts
    from alte.registration.register import RegistrationCounts
    from alte.types import Counts

    poses = PoseCounts(frames=3, kept={"weak": 1})
    out = poses.as_dict()
    poses.kept["weak"] += 1
    poses.scans.append({"scan": 0})
    assert out["frames"] == 3 and out["kept"] == {"weak": 1} and out["scans"] == []
    for counter in (ReadCounts(), DeskewCounts(), RegistrationCounts(), poses):
        assert isinstance(counter, Counts)
        assert set(counter.as_dict()) == set(vars(counter))
