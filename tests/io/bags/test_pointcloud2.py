"""Tests for alte.io.bags.pointcloud2: every field layout decodes to the same x, y, z."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
from rosbags.typesys import Stores, get_typestore

from alte.errors import BagError
from alte.io.bags.pointcloud2 import decode_pointcloud2, decode_timed, encode_pointcloud2

TS = get_typestore(Stores.ROS2_HUMBLE)


CODES = {"i1": 1, "u1": 2, "i2": 3, "u2": 4, "i4": 5, "u4": 6, "f4": 7, "f8": 8}


def make_msg(points, layout, *, point_step=None, height=1, row_pad=0, bigendian=False):
    """Hand-built PointCloud2-like message: ``layout`` = [(name, numpy code, offset)]."""
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    order = ">" if bigendian else "<"
    dtype = np.dtype({
        "names": [n for n, _, _ in layout],
        "formats": [order + c for _, c, _ in layout],
        "offsets": [o for _, _, o in layout],
        "itemsize": point_step or max(o + np.dtype(c).itemsize for _, c, o in layout),
    })
    rec = np.zeros(len(pts), dtype=dtype)
    for axis, name in enumerate("xyz"):
        if name in dtype.names:
            rec[name] = pts[:, axis]
    width = len(pts) // height
    rows = rec.tobytes()
    row_bytes = width * dtype.itemsize
    data = b"".join(rows[r * row_bytes:(r + 1) * row_bytes] + b"\xab" * row_pad
                    for r in range(height))
    fields = [SimpleNamespace(name=n, offset=o, datatype=CODES[c], count=1) for n, c, o in layout]
    return SimpleNamespace(
        height=height, width=width, fields=fields, is_bigendian=bigendian,
        point_step=dtype.itemsize, row_step=row_bytes + row_pad,
        data=np.frombuffer(data, np.uint8), is_dense=True,
    )


XYZ32 = [("x", "f4", 0), ("y", "f4", 4), ("z", "f4", 8)]
PTS = np.random.default_rng(1).uniform(-50, 50, (12, 3))


def test_float64_is_exact():
    msg = make_msg(PTS, [("x", "f8", 0), ("y", "f8", 8), ("z", "f8", 16)])
    points, dropped = decode_pointcloud2(msg)
    assert dropped == 0
    assert points.dtype == np.float64 and np.array_equal(points, PTS)


def test_float32_with_extra_fields_and_padding():
    layout = [("x", "f4", 0), ("y", "f4", 4), ("z", "f4", 8), ("intensity", "f4", 16),
              ("ring", "u2", 20), ("time", "f8", 24)]
    msg = make_msg(PTS, layout, point_step=48)
    points, dropped = decode_pointcloud2(msg)
    assert dropped == 0 and points.shape == (12, 3)
    np.testing.assert_allclose(points, PTS.astype(np.float32), rtol=0, atol=0)


def test_field_order_and_offsets_are_respected():
    layout = [("intensity", "f4", 0), ("z", "f4", 4), ("x", "f4", 8), ("y", "f4", 12)]
    points, _ = decode_pointcloud2(make_msg(PTS, layout, point_step=20))
    np.testing.assert_array_equal(points, PTS.astype(np.float32).astype(np.float64))


def test_organized_cloud_with_row_padding():
    msg = make_msg(PTS, XYZ32, height=3, row_pad=7)
    assert msg.row_step == 4 * 12 + 7
    points, _ = decode_pointcloud2(msg)
    np.testing.assert_array_equal(points, PTS.astype(np.float32).astype(np.float64))


def test_big_endian():
    msg = make_msg(PTS, [("x", "f8", 0), ("y", "f8", 8), ("z", "f8", 16)], bigendian=True)
    points, _ = decode_pointcloud2(msg)
    np.testing.assert_array_equal(points, PTS)


def test_integer_coordinates():
    layout = [("x", "i2", 0), ("y", "i2", 2), ("z", "i2", 4)]
    ints = np.round(PTS)
    points, _ = decode_pointcloud2(make_msg(ints, layout))
    np.testing.assert_array_equal(points, ints)


def test_nonfinite_points_are_dropped_and_counted():
    pts = PTS.copy()
    pts[2, 0], pts[5, 2], pts[7] = np.nan, np.inf, -np.inf
    points, dropped = decode_pointcloud2(make_msg(pts, XYZ32))
    assert dropped == 3
    np.testing.assert_array_equal(points, np.delete(pts, [2, 5, 7], 0).astype(np.float32))


def test_zero_points():
    points, dropped = decode_pointcloud2(make_msg(np.empty((0, 3)), XYZ32))
    assert points.shape == (0, 3) and dropped == 0


def test_missing_field_names_topic():
    msg = make_msg(PTS, [("x", "f4", 0), ("y", "f4", 4), ("zz", "f4", 8)])
    with pytest.raises(BagError, match=r"/lidar: PointCloud2 has no z field"):
        decode_pointcloud2(msg, "/lidar")


def test_point_step_too_small():
    msg = make_msg(PTS, XYZ32)
    msg.point_step, msg.row_step = 8, 8 * 12
    with pytest.raises(BagError, match=r"point_step 8 is smaller than the 12 bytes"):
        decode_pointcloud2(msg, "/lidar")


def test_data_length_inconsistent():
    msg = make_msg(PTS, XYZ32)
    msg.data = msg.data[:-4]
    with pytest.raises(BagError, match=r"/lidar: data has 140 bytes, expected .* = 144"):
        decode_pointcloud2(msg, "/lidar")


def test_row_step_too_small():
    msg = make_msg(PTS, XYZ32, height=2)
    msg.row_step = 10
    with pytest.raises(BagError, match=r"row_step 10 < width 6"):
        decode_pointcloud2(msg, "/lidar")


def test_unknown_datatype():
    msg = make_msg(PTS, XYZ32)
    msg.fields[1].datatype = 11
    with pytest.raises(BagError, match=r"field 'y' has unknown datatype 11"):
        decode_pointcloud2(msg, "/lidar")


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_encode_round_trip_through_cdr(dtype):
    intensity = np.arange(12, dtype=np.float32)
    ring = np.arange(12, dtype=np.uint16)
    msg = encode_pointcloud2(PTS, 5 * 10**9 + 7, "velodyne", TS, dtype=dtype,
                             extra_fields={"intensity": intensity, "ring": ring})
    back = TS.deserialize_cdr(TS.serialize_cdr(msg, msg.__msgtype__), msg.__msgtype__)
    assert (back.header.stamp.sec, back.header.stamp.nanosec) == (5, 7)
    assert [f.name for f in back.fields] == ["x", "y", "z", "intensity", "ring"]
    assert back.point_step == 3 * np.dtype(dtype).itemsize + 4 + 2
    points, dropped = decode_pointcloud2(back)
    assert dropped == 0
    np.testing.assert_array_equal(points, PTS.astype(dtype).astype(np.float64))


def test_encode_rejects_bad_shapes():
    with pytest.raises(BagError, match=r"frame 'velodyne' must have shape \(N, 3\)"):
        encode_pointcloud2(np.zeros((4, 2)), 0, "velodyne", TS)
    with pytest.raises(BagError, match=r"extra field 'intensity' must be N=12"):
        encode_pointcloud2(PTS, 0, "velodyne", TS, extra_fields={"intensity": np.zeros(3)})


STAMP = 1_630_577_808_570_040_832
SWEEP = np.linspace(0.0, 0.099, len(PTS))


@pytest.mark.parametrize(("name", "values"), [
    ("t", (SWEEP * 1e9).astype(np.uint32)),                       # Ouster: ns from the stamp
    ("time", SWEEP.astype(np.float32)),                           # Velodyne: s from the stamp
    ("timestamp", STAMP * 1e-9 + SWEEP),                          # Hesai: absolute s
    ("offset_time", (SWEEP * 1e9).astype(np.int32))])              # Livox: ns
def test_per_point_time_in_seconds_from_the_stamp(name, values):
    msg = encode_pointcloud2(PTS, STAMP, "lidar", TS, extra_fields={name: values})
    points, times, dropped = decode_timed(msg, STAMP)
    assert dropped == 0 and np.allclose(points, PTS, atol=1e-4)
    assert times is not None and np.allclose(times, SWEEP, atol=2e-6)
    assert decode_timed(encode_pointcloud2(PTS, STAMP, "lidar", TS), STAMP)[1] is None


def test_per_point_time_follows_dropped_points():
    pts = PTS.copy()
    pts[3] = np.nan
    msg = encode_pointcloud2(pts, STAMP, "lidar", TS, extra_fields={"time": SWEEP})
    points, times, dropped = decode_timed(msg, STAMP)
    assert dropped == 1 and times is not None and len(times) == len(points) == len(PTS) - 1
    assert np.allclose(times, np.delete(SWEEP, 3))


def test_per_point_time_in_an_unknown_unit_is_an_error():
    micro = (SWEEP * 1e6).astype(np.float64)  # microseconds in a float field
    msg = encode_pointcloud2(PTS, STAMP, "lidar", TS, extra_fields={"time": micro})
    with pytest.raises(BagError, match=r"/points: per-point time field 'time' spans 0\.\.99000"):
        decode_timed(msg, STAMP, "/points")
