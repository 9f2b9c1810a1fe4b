"""Tests for alte.io.bags.velodyne: synthetic packets with known geometry, plus tier4/nebula's
own decoding of a real VLP-16 recording."""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from scipy.spatial import cKDTree

from alte.errors import BagError, ParameterError
from alte.io.bags.velodyne import (
    PACKET_SIZE,
    VLP16_ELEVATIONS_DEG,
    decode_velodyne_packets,
    decode_velodyne_scan,
    register_velodyne_types,
)
from alte.paths import realdata_dir

REALDATA = realdata_dir()
VLP_DIR = REALDATA / "vlp16_packets"
MODE = {"strongest": 0x37, "last": 0x38, "dual": 0x39}
#: The VLP-16 user manual's table of laser IDs and vertical angles (ch. 9): laser 0 looks
#: 15 deg down, laser 1 one degree up, and so on, interleaved in 2 deg steps.
MANUAL_ELEVATION_DEG = {0: -15, 1: 1, 2: -13, 3: 3, 4: -11, 5: 5, 6: -9, 7: 7,
                        8: -7, 9: 9, 10: -5, 11: 11, 12: -3, 13: 13, 14: -1, 15: 15}


def make_packet(azimuth, dist_mm, refl=None, mode="strongest", product=0x22):
    """One raw packet from block azimuths (12,) [0.01 deg] and distances (12, 32) [mm]."""
    dist_mm = np.asarray(dist_mm, dtype=np.float64)
    refl = np.zeros((12, 32), np.uint8) if refl is None else np.asarray(refl, np.uint8)
    raw = np.zeros(PACKET_SIZE, np.uint8)
    body = raw[:1200].reshape(12, 100)
    body[:, 0], body[:, 1] = 0xFF, 0xEE
    body[:, 2:4] = np.asarray(azimuth, "<u2").view(np.uint8).reshape(12, 2)
    records = body[:, 4:].reshape(12, 32, 3)
    units = np.round(dist_mm / 2.0).astype("<u2")
    records[:, :, :2] = units.view(np.uint8).reshape(12, 32, 2)
    records[:, :, 2] = refl
    raw[1204], raw[1205] = MODE.get(mode, mode), product
    return raw


def one_return(block=0, channel=0, metres=10.0, shape=(12, 32)):
    dist = np.zeros(shape)
    dist[block, channel] = metres * 1000.0
    return dist


def steady_azimuths(start=0, step=20, n=12):
    return (start + step * np.arange(n)) % 36000


# ---------------------------------------------------------------- geometry


def test_the_elevation_table_is_the_manuals():
    assert VLP16_ELEVATIONS_DEG.tolist() == [MANUAL_ELEVATION_DEG[i] for i in range(16)]


@pytest.mark.parametrize("channel", range(16))
def test_each_laser_elevation_and_manual_frame(channel):
    az = np.full(12, 9000)  # 90 deg: the manual frame's +x
    pkt = make_packet(az, one_return(0, channel, 10.0))
    pts = decode_velodyne_packets(pkt[None], interpolation="none")
    w = np.deg2rad(MANUAL_ELEVATION_DEG[channel])
    np.testing.assert_allclose(pts, [[10 * np.cos(w), 0.0, 10 * np.sin(w)]], atol=1e-9)
    # channel + 16 is the same laser in the block's second firing sequence
    second = decode_velodyne_packets(make_packet(az, one_return(0, channel + 16, 10.0))[None],
                                     interpolation="none")
    np.testing.assert_allclose(second, pts, atol=1e-9)


def test_azimuth_zero_looks_along_manual_y_and_ros_x():
    pkt = make_packet(np.zeros(12), one_return(0, 1, 4.0))[None]  # laser 1: +1 deg
    manual = decode_velodyne_packets(pkt, interpolation="none")
    ros = decode_velodyne_packets(pkt, frame="ros", interpolation="none")
    w = np.deg2rad(1.0)
    np.testing.assert_allclose(manual, [[0.0, 4 * np.cos(w), 4 * np.sin(w)]], atol=1e-12)
    np.testing.assert_allclose(ros, [[4 * np.cos(w), 0.0, 4 * np.sin(w)]], atol=1e-12)


def test_ros_frame_is_manual_frame_turned_minus_90_deg():
    rng = np.random.default_rng(1)
    pkt = make_packet(steady_azimuths(1234), rng.uniform(500, 50000, (12, 32)))[None]
    manual = decode_velodyne_packets(pkt)
    ros = decode_velodyne_packets(pkt, frame="ros")
    np.testing.assert_allclose(ros, np.column_stack([manual[:, 1], -manual[:, 0], manual[:, 2]]))


def _azimuth_deg(points):
    return np.rad2deg(np.arctan2(points[:, 0], points[:, 1])) % 360.0


@pytest.mark.parametrize(
    ("block", "channel", "expected"),
    [
        (0, 0, 1.00),  # first laser of first sequence: the block azimuth
        (0, 16, 1.10),  # second sequence: half-way to the next block (55.296 / 110.592)
        (3, 31, 1.60 + 0.2 * (55.296 + 15 * 2.304) / 110.592),
        (11, 16, 3.20 + 0.10),  # last block repeats the previous step
    ],
)
def test_manual_interpolation_between_blocks(block, channel, expected):
    pkt = make_packet(steady_azimuths(100), one_return(block, channel, 5.0))
    pts = decode_velodyne_packets(pkt[None])
    assert _azimuth_deg(pts)[0] == pytest.approx(expected, abs=1e-9)


def test_interpolation_handles_the_36000_wrap():
    az = steady_azimuths(35960)  # 359.6, 359.8, 0.0, ...
    pkt = make_packet(az, one_return(1, 16, 5.0))
    assert _azimuth_deg(decode_velodyne_packets(pkt[None]))[0] == pytest.approx(359.9, abs=1e-9)


def test_interpolation_none_and_nebula_last_block():
    pkt = make_packet(steady_azimuths(100), one_return(11, 16, 5.0))[None]
    assert _azimuth_deg(decode_velodyne_packets(pkt, interpolation="none"))[0] == pytest.approx(3.2)
    nebula = decode_velodyne_packets(pkt, interpolation="nebula")
    assert _azimuth_deg(nebula)[0] == pytest.approx(3.2)  # nebula does not interpolate it


def test_zero_distances_and_min_range_are_dropped():
    dist = np.zeros((12, 32))
    dist[0, :3] = [0.0, 250.0, 5000.0]
    pkt = make_packet(steady_azimuths(), dist)[None]
    assert len(decode_velodyne_packets(pkt)) == 2
    pts = decode_velodyne_packets(pkt, min_range=0.3)
    assert len(pts) == 1
    assert np.linalg.norm(pts[0]) == pytest.approx(5.0)


def test_several_packets_decode_like_each_alone():
    rng = np.random.default_rng(2)
    pkts = [make_packet(steady_azimuths(s), rng.uniform(500, 9000, (12, 32))) for s in (0, 240)]
    both = decode_velodyne_packets(np.stack(pkts))
    alone = np.vstack([decode_velodyne_packets(p[None]) for p in pkts])
    np.testing.assert_array_equal(both, alone)
    assert both.shape == (2 * 12 * 32, 3)
    assert both.dtype == np.float64


# ---------------------------------------------------------------- return modes


def _dual_packet():
    """Pairs (last, strongest): channel 0 single echo, channel 1 strongest is nearer,
    channel 2 the last echo is the strongest (so the strongest block holds the second)."""
    az = np.repeat(steady_azimuths(0, 40, 6), 2)
    dist, refl = np.zeros((12, 32)), np.zeros((12, 32))
    dist[0:2, 0], refl[0:2, 0] = 3000.0, 50
    dist[0, 1], dist[1, 1], refl[0, 1], refl[1, 1] = 8000.0, 4000.0, 10, 90
    dist[0, 2], dist[1, 2], refl[0, 2], refl[1, 2] = 9000.0, 6000.0, 80, 20
    return make_packet(az, dist, refl, mode="dual")[None]


@pytest.mark.parametrize(
    ("mode", "ranges"),
    [
        ("last", [3.0, 8.0, 9.0]),
        ("strongest", [3.0, 4.0, 9.0]),
        ("dual", [3.0, 8.0, 4.0, 9.0, 6.0]),
    ],
)
def test_dual_return_selection(mode, ranges):
    pts = decode_velodyne_packets(_dual_packet(), return_mode=mode)
    np.testing.assert_allclose(np.sort(np.linalg.norm(pts, axis=1)), np.sort(ranges))


def test_dual_pair_shares_the_azimuth():
    pts = decode_velodyne_packets(_dual_packet(), return_mode="dual")
    ranges = np.linalg.norm(pts, axis=1)
    az = _azimuth_deg(pts)
    channel1 = np.isclose(ranges, 8.0) | np.isclose(ranges, 4.0)  # its last and strongest echo
    assert channel1.sum() == 2
    assert np.ptp(az[channel1]) < 1e-9


def test_single_return_packets_accept_dual_and_own_mode():
    pkt = make_packet(steady_azimuths(), one_return(), mode="last")[None]
    assert len(decode_velodyne_packets(pkt, return_mode="last")) == 1
    assert len(decode_velodyne_packets(pkt, return_mode="dual")) == 1


def test_empty_packet_array_gives_no_points():
    pts = decode_velodyne_packets(np.zeros((0, PACKET_SIZE), np.uint8))
    assert pts.shape == (0, 3)


# ---------------------------------------------------------------- errors


@pytest.mark.parametrize(
    "data",
    [
        np.zeros((2, 1200), np.uint8),
        np.zeros(PACKET_SIZE, np.uint8),
        np.zeros((1, PACKET_SIZE), np.int16),
    ],
)
def test_wrong_packet_array_shape_or_dtype(data):
    with pytest.raises(BagError, match=r"\(P, 1206\) uint8"):
        decode_velodyne_packets(data)


def test_missing_block_flag():
    pkt = make_packet(steady_azimuths(), one_return())
    pkt[300] = 0x00  # block 3 flag
    with pytest.raises(BagError, match=r"packet 1 .*0xFFEE"):
        decode_velodyne_packets(np.stack([make_packet(steady_azimuths(), one_return()), pkt]))


def test_unknown_return_mode_byte_and_mixed_modes():
    bad = make_packet(steady_azimuths(), one_return(), mode=0x41)[None]
    with pytest.raises(BagError, match="return mode byte"):
        decode_velodyne_packets(bad)
    mixed = np.stack([make_packet(steady_azimuths(), one_return(), mode=m) for m in MODE])
    with pytest.raises(BagError, match="return mode byte"):
        decode_velodyne_packets(mixed)


def test_not_a_vlp16():
    pkt = make_packet(steady_azimuths(), one_return(), product=0x28)[None]
    with pytest.raises(BagError, match=r"product id.*0x28.*VLP-16"):
        decode_velodyne_packets(pkt)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"return_mode": "first"}, "return_mode='first'"),
        ({"frame": "enu"}, "frame='enu'"),
        ({"interpolation": "cubic"}, "interpolation='cubic'"),
        ({"min_range": -1.0}, "min_range"),
        ({"min_range": float("nan")}, "min_range"),
    ],
)
def test_bad_parameters(kwargs, match):
    pkt = make_packet(steady_azimuths(), one_return())[None]
    with pytest.raises(ParameterError, match=match):
        decode_velodyne_packets(pkt, **kwargs)


def test_mode_the_packets_do_not_carry():
    pkt = make_packet(steady_azimuths(), one_return(), mode="last")[None]
    with pytest.raises(ParameterError, match="carry 'last' returns only"):
        decode_velodyne_packets(pkt, return_mode="strongest")


def test_decode_scan_message():
    pkt = make_packet(steady_azimuths(), one_return(0, 0, 7.0))
    msg = SimpleNamespace(packets=[SimpleNamespace(data=pkt), SimpleNamespace(data=pkt)])
    assert decode_velodyne_scan(msg).shape == (2, 3)
    assert decode_velodyne_scan(SimpleNamespace(packets=[])).shape == (0, 3)
    with pytest.raises(BagError, match="not a velodyne_msgs/msg/VelodyneScan"):
        decode_velodyne_scan(SimpleNamespace(header=None))
    short = SimpleNamespace(packets=[SimpleNamespace(data=pkt), SimpleNamespace(data=pkt[:100])])
    with pytest.raises(BagError, match="differ in size"):
        decode_velodyne_scan(short)


def test_register_types_is_idempotent_and_reports_conflicts():
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    store = get_typestore(Stores.ROS2_HUMBLE)
    register_velodyne_types(store)
    register_velodyne_types(store)
    assert "velodyne_msgs/msg/VelodyneScan" in store.types
    other = get_typestore(Stores.ROS2_HUMBLE)
    other.register(get_types_from_msg("uint8[10] data", "velodyne_msgs/msg/VelodynePacket"))
    with pytest.raises(BagError, match="velodyne_msgs"):
        register_velodyne_types(other)


# ---------------------------------------------------------------- real recording


def _read_reference(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """xyz of nebula's binary PCD and its per-point distance field."""
    raw = path.read_bytes()
    start = raw.index(b"DATA binary\n") + len(b"DATA binary\n")
    dtype = np.dtype(
        [("xyz", "<f4", 3), ("intensity", "u1"), ("return_type", "u1"), ("channel", "<u2")]
        + [(n, "<f4") for n in ("azimuth", "elevation", "distance")]
        + [("time_stamp", "<u4")]
    )
    ref = np.frombuffer(raw[start:], dtype)
    return ref["xyz"].astype(np.float64), ref["distance"].astype(np.float64)


@pytest.fixture(scope="module")
def nebula_scan4():
    if not (VLP_DIR / "bag").is_dir() or not (VLP_DIR / "reference_decoded.pcd").is_file():
        pytest.skip("../shared/realdata/vlp16_packets absent")
    from rosbags.highlevel import AnyReader
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS2_HUMBLE)
    register_velodyne_types(store)
    with AnyReader([VLP_DIR / "bag"], default_typestore=store) as reader:
        msgs = [reader.deserialize(raw, con.msgtype) for con, _, raw in reader.messages()]
    xyz, dist = _read_reference(VLP_DIR / "reference_decoded.pcd")
    return msgs, xyz, dist


@pytest.mark.realdata
def test_real_bag_has_four_dual_return_rotations(nebula_scan4):
    msgs, xyz, _ = nebula_scan4
    assert len(msgs) == 4
    assert len(xyz) == 14831
    for msg in msgs:
        pts = decode_velodyne_scan(msg, "dual")
        assert 14000 < len(pts) < 16000
        assert np.isfinite(pts).all()


@pytest.mark.realdata
def test_matches_nebula_reference_decoding(nebula_scan4):
    """nebula's test config: dual returns, ROS frame, min range 0.3 m; its quirks reproduced."""
    msgs, xyz, _ = nebula_scan4
    ours = decode_velodyne_scan(msgs[3], "dual", frame="ros", min_range=0.3, interpolation="nebula")
    dist, _ = cKDTree(ours).query(xyz)
    assert np.mean(dist < 0.01) >= 0.99
    assert np.mean(dist < 0.001) >= 0.97
    assert np.linalg.norm(ours, axis=1).min() > 0.3


@pytest.mark.realdata
def test_manual_interpolation_differs_from_nebula_by_at_most_one_firing_block(nebula_scan4):
    """Our default timing moves points only along the rotation, by less than one block pair."""
    msgs, xyz, ref_range = nebula_scan4
    ours = decode_velodyne_scan(msgs[3], "dual", frame="ros", min_range=0.3)
    dist, _ = cKDTree(ours).query(xyz)
    bound = 0.01 + ref_range * np.deg2rad(0.45)  # one pair = 110.6 us = 0.4 deg at 600 rpm
    assert np.mean(dist < bound) >= 0.995
    assert np.mean(dist < 0.01) < 0.99  # the timing models really differ
    none, _ = cKDTree(decode_velodyne_scan(msgs[3], "dual", "ros", 0.3, "none")).query(xyz)
    assert np.mean(none < 0.001) < 0.5 < np.mean(dist < 0.001)  # the refinement matters
