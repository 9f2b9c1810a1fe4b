"""Raw Velodyne VLP-16 packet decoding: ``velodyne_msgs/VelodyneScan`` -> (N, 3) points.

Packet layout (VLP-16 user manual, ch. 9): 12 data blocks of 100 bytes (flag 0xFFEE,
azimuth in 0.01 deg, 32 records of distance (2 mm units) + reflectivity), a 4-byte
timestamp and two factory bytes (return mode, product id). Each block holds two firing
sequences of the 16 lasers; every laser fires 2.304 us after the previous one and the
second sequence 55.296 us after the first, so each point's azimuth is interpolated from
the block azimuth towards the next block's (the manual's precise azimuth; tier4/nebula
does the same except for quirks that ``interpolation="nebula"`` reproduces, needed to
match nebula's reference decoding to 1 cm). In dual-return packets blocks come in pairs
(last, strongest) sharing one azimuth; when the strongest echo is also the last, the
"strongest" block carries the second-strongest, so the strongest of a pair is the one
with the higher reflectivity.

Frames: ``"manual"`` (default) is the VLP-16 manual's sensor frame, ``x = r cos w sin a``,
``y = r cos w cos a``: azimuth 0 looks along +y, the axis the thesis' mount uses.
``"ros"`` is the ROS driver / nebula frame (x forward = manual y, y = -manual x).
Everything is vectorized over packets, blocks and lasers.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from alte.errors import BagError, ParameterError
from alte.io.bags.messages import VelodyneScanMsg

if TYPE_CHECKING:
    from rosbags.typesys.store import Typestore

__all__ = [
    "FRAMES",
    "INTERPOLATIONS",
    "PACKET_SIZE",
    "RETURN_MODES",
    "VLP16_ELEVATIONS_DEG",
    "decode_velodyne_packets",
    "decode_velodyne_scan",
    "register_velodyne_types",
]

PACKET_SIZE = 1206
RETURN_MODES = ("strongest", "last", "dual")
FRAMES = ("manual", "ros")
INTERPOLATIONS = ("manual", "none", "nebula")
VLP16_ELEVATIONS_DEG = np.array(
    [-15, 1, -13, 3, -11, 5, -9, 7, -7, 9, -5, 11, -3, 13, -1, 15], dtype=np.float64
)

_PACKET_MSG = "builtin_interfaces/Time stamp\nuint8[1206] data\n"
_SCAN_MSG = "std_msgs/Header header\nvelodyne_msgs/VelodynePacket[] packets\n"
_MODE_BYTES = {0x37: "strongest", 0x38: "last", 0x39: "dual"}
_PRODUCT_VLP16 = 0x22
_BLOCK_FLAG = 0xEEFF  # bytes FF EE read as little-endian uint16
_DISTANCE_UNIT_M = 0.002
_FIRING_US = 2.304
_SEQUENCE_US = 55.296
_BLOCK_US = 2 * _SEQUENCE_US

# each channel record interleaves a uint16 distance and a uint8 reflectivity
_RECORD = np.dtype([("dist", "<u2"), ("refl", "u1")])
_RAW_BLOCK = np.dtype([("flag", "<u2"), ("azimuth", "<u2"), ("rec", _RECORD, (2, 16))])
_PACKET = np.dtype(
    [("blocks", _RAW_BLOCK, (12,)), ("stamp", "<u4"), ("mode", "u1"), ("product", "u1")]
)


def register_velodyne_types(typestore: Typestore) -> None:
    """Register ``velodyne_msgs/msg/VelodynePacket`` and ``VelodyneScan`` in a rosbags typestore.

    Bags do not store these definitions. Registering twice is harmless.
    """
    from rosbags.typesys import TypesysError, get_types_from_msg

    try:
        typestore.register(get_types_from_msg(_PACKET_MSG, "velodyne_msgs/msg/VelodynePacket"))
        typestore.register(get_types_from_msg(_SCAN_MSG, "velodyne_msgs/msg/VelodyneScan"))
    except TypesysError as err:
        raise BagError(f"cannot register velodyne_msgs types: {err}") from err


def _parse(data: NDArray[np.uint8]) -> NDArray[np.void]:
    """View a (P, 1206) uint8 array as structured packets after checking shape and flags."""
    arr = np.asarray(data)
    if arr.dtype != np.uint8 or arr.ndim != 2 or arr.shape[1] != PACKET_SIZE:
        raise BagError(
            f"Velodyne packets must be a (P, {PACKET_SIZE}) uint8 array, "
            f"got shape {arr.shape} dtype {arr.dtype}"
        )
    packets = np.ascontiguousarray(arr).view(_PACKET)[:, 0]
    bad = np.flatnonzero((packets["blocks"]["flag"] != _BLOCK_FLAG).any(axis=1))
    if bad.size:
        raise BagError(
            f"Velodyne packet {int(bad[0])} (of {len(packets)}) has a data block without "
            f"the 0xFFEE flag: not VLP-16 data or corrupt ({bad.size} bad packets)"
        )
    products = np.unique(packets["product"])
    if products.size and (products != _PRODUCT_VLP16).any():
        raise BagError(
            f"Velodyne packets have product id(s) {[hex(p) for p in products]}, "
            f"expected {hex(_PRODUCT_VLP16)} (VLP-16)"
        )
    return packets


def _packet_mode(packets: NDArray[np.void]) -> str:
    """The return mode the packets were recorded in (all packets must agree)."""
    modes = np.unique(packets["mode"])
    if modes.size != 1 or int(modes[0]) not in _MODE_BYTES:
        raise BagError(
            f"Velodyne packets have return mode byte(s) {[hex(m) for m in modes]}; "
            "expected one of 0x37 strongest, 0x38 last, 0x39 dual"
        )
    return _MODE_BYTES[int(modes[0])]


def _block_steps(
    azimuth: NDArray[np.uint16], dual: bool, interpolation: str
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Start azimuth and step to the next firing block (both 0.01 deg, shape (P, 12))."""
    az = azimuth.astype(np.float64)
    stride = 2 if dual else 1
    start, step = az.copy(), np.zeros_like(az)
    if interpolation == "none":
        return start, step
    step[:, :-stride] = np.mod(az[:, stride:] - az[:, :-stride], 36000.0)
    if interpolation == "manual":
        step[:, -stride:] = step[:, -2 * stride : -stride]  # the manual: repeat the last step
        if dual:  # both blocks of a pair fire together: use the first block's azimuth
            start[:, 1::2], step[:, 1::2] = start[:, 0::2], step[:, 0::2]
    elif dual:  # nebula: strongest blocks take the next pair's azimuth, uninterpolated
        start[:, 1:-1:2] = az[:, 2::2]
        step[:, 1::2] = 0.0
    return start, step


def _point_azimuth(azimuth: NDArray[np.uint16], dual: bool, interpolation: str
                   ) -> NDArray[np.float64]:
    """Per-point azimuth (radians), shape (P, 12, 2, 16), from block azimuths (P, 12)."""
    laser = np.arange(16) * _FIRING_US
    offset = (laser[None, :] + np.arange(2)[:, None] * _SEQUENCE_US) / _BLOCK_US  # (2, 16)
    start, step = _block_steps(azimuth, dual, interpolation)
    centi = start[..., None, None] + step[..., None, None] * offset
    if interpolation == "nebula":
        centi = np.round(centi)  # nebula looks azimuths up in a 0.01 deg table
    return np.deg2rad(np.mod(centi, 36000.0) / 100.0)


def _select_returns(
    packets: NDArray[np.void], recorded: str, return_mode: str, interpolation: str
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Distances (m) and azimuths (rad), shape (..., 2, 16), of the requested returns."""
    blocks = packets["blocks"]
    dist = blocks["rec"]["dist"].astype(np.float64) * _DISTANCE_UNIT_M
    azimuth = _point_azimuth(blocks["azimuth"], recorded == "dual", interpolation)
    if recorded != "dual":
        if return_mode not in ("dual", recorded):
            raise ParameterError(
                f"return_mode={return_mode!r} but the packets carry {recorded!r} returns only; "
                f"use return_mode={recorded!r}"
            )
        return dist, azimuth
    last, other = dist[:, 0::2], dist[:, 1::2]
    if return_mode == "last":
        return last, azimuth[:, 0::2]
    if return_mode == "strongest":
        refl = blocks["rec"]["refl"]
        pick = refl[:, 1::2] > refl[:, 0::2]
        return np.where(pick, other, last), np.where(pick, azimuth[:, 1::2], azimuth[:, 0::2])
    second = np.where(other != last, other, 0.0)  # a single echo fills both blocks
    return np.stack([last, second], axis=2), np.stack([azimuth[:, 0::2], azimuth[:, 1::2]], 2)


def _to_xyz(dist: NDArray[np.float64], azimuth: NDArray[np.float64], frame: str, min_range: float
            ) -> NDArray[np.float64]:
    """Polar (distance, azimuth, laser elevation) -> Cartesian, dropping ranges <= min_range."""
    elev = np.broadcast_to(np.deg2rad(VLP16_ELEVATIONS_DEG), dist.shape)
    keep = dist > min_range
    r, a, w = dist[keep], azimuth[keep], elev[keep]
    horizontal = r * np.cos(w)
    sin_a, cos_a = horizontal * np.sin(a), horizontal * np.cos(a)
    xy = (sin_a, cos_a) if frame == "manual" else (cos_a, -sin_a)
    return np.column_stack([xy[0], xy[1], r * np.sin(w)])


def decode_velodyne_packets(
    data: NDArray[np.uint8],
    return_mode: str = "strongest",
    frame: str = "manual",
    min_range: float = 0.0,
    interpolation: str = "manual",
) -> NDArray[np.float64]:
    """Decode raw VLP-16 packets (P, 1206) uint8 into (N, 3) float64 points in metres.

    ``return_mode`` picks from dual-return packets: ``"strongest"``, ``"last"`` or
    ``"dual"`` (every last echo plus each strongest echo that differs from it, as nebula
    does). Single-return packets decode with their own mode or ``"dual"``. Points at
    ranges ``<= min_range`` (zero distance = no echo) are dropped. ``interpolation``
    places each laser firing between block azimuths: ``"manual"`` (the user manual's
    timing, the last block extrapolates the previous step), ``"none"`` (block azimuth
    for all 32 firings) or ``"nebula"`` (tier4/nebula's output, used to validate
    against it: the last block (pair) of a packet is not interpolated and, in dual
    mode, strongest blocks take the next pair's azimuth).
    """
    if return_mode not in RETURN_MODES:
        raise ParameterError(f"return_mode={return_mode!r}; expected one of {RETURN_MODES}")
    if frame not in FRAMES:
        raise ParameterError(f"frame={frame!r}; expected one of {FRAMES}")
    if interpolation not in INTERPOLATIONS:
        raise ParameterError(f"interpolation={interpolation!r}; expected one of {INTERPOLATIONS}")
    if not np.isfinite(min_range) or min_range < 0:
        raise ParameterError(f"min_range={min_range!r} must be a finite number >= 0")
    packets = _parse(data)
    if packets.size == 0:
        return np.empty((0, 3), dtype=np.float64)
    recorded = _packet_mode(packets)
    dist, azimuth = _select_returns(packets, recorded, return_mode, interpolation)
    return _to_xyz(dist, azimuth, frame, float(min_range))


def decode_velodyne_scan(
    msg: VelodyneScanMsg,
    return_mode: str = "strongest",
    frame: str = "manual",
    min_range: float = 0.0,
    interpolation: str = "manual",
) -> NDArray[np.float64]:
    """Decode one ``velodyne_msgs/msg/VelodyneScan`` message (all its packets) into (N, 3).

    Anything without packets (an untyped caller's wrong message) is a :class:`BagError`.
    """
    if not isinstance(msg, VelodyneScanMsg):
        raise BagError(f"{type(msg).__name__} is not a velodyne_msgs/msg/VelodyneScan")
    packets = msg.packets
    if len(packets) == 0:
        data = np.empty((0, PACKET_SIZE), dtype=np.uint8)
    else:
        try:
            data = np.stack([np.asarray(p.data, dtype=np.uint8) for p in packets])
        except ValueError as err:
            raise BagError(f"VelodyneScan packets differ in size: {err}") from err
    return decode_velodyne_packets(data, return_mode, frame, min_range, interpolation)
