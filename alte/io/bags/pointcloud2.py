"""``sensor_msgs/msg/PointCloud2`` <-> (N, 3) float64 arrays, any field layout.

Decoding builds one numpy structured dtype from the message's ``fields`` (offsets,
datatypes, counts, endianness, ``point_step`` padding) and views the data buffer
through it, so no Python loop ever touches a point. Organized clouds with row
padding (``row_step > width * point_step``) are cut to their payload first.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING, Literal

import numpy as np
from numpy.typing import NDArray

from alte.errors import BagError
from alte.io.bags.messages import PointCloud2Msg
from alte.types import finite_rows

if TYPE_CHECKING:  # rosbags declares MsgType (its message classes' type) for checkers only
    from rosbags.typesys.store import MsgType, Typestore

__all__ = [
    "POINTFIELD_DTYPES",
    "TIME_FIELDS",
    "CoordType",
    "decode_pointcloud2",
    "decode_timed",
    "encode_pointcloud2",
    "make_header",
    "make_time",
]

#: ``sensor_msgs/PointField`` datatype code -> numpy scalar type.
POINTFIELD_DTYPES: dict[int, np.dtype[np.generic[object]]] = {
    1: np.dtype(np.int8),
    2: np.dtype(np.uint8),
    3: np.dtype(np.int16),
    4: np.dtype(np.uint16),
    5: np.dtype(np.int32),
    6: np.dtype(np.uint32),
    7: np.dtype(np.float32),
    8: np.dtype(np.float64),
}
#: The scalar types a ``PointField`` can hold (its datatypes 1-8).
_Numeric = (np.int8 | np.uint8 | np.int16 | np.uint16 | np.int32 | np.uint32 | np.float32
            | np.float64)
#: Storage type of x, y, z when encoding (float32 like real drivers, float64 lossless).
CoordType = type[np.float32] | type[np.float64]
_CODES = {dt: code for code, dt in POINTFIELD_DTYPES.items()}
_XYZ = ("x", "y", "z")
#: Per-point time fields, in the order they are looked for (Ouster ``t``, Velodyne ``time``,
#: Hesai ``timestamp``, Livox ``offset_time``).
TIME_FIELDS = ("t", "time", "timestamp", "offset_time")
#: Per-point times further than this from the scan stamp (s) mean a unit the reader missed.
_MAX_SPAN_S = 2.0


def _xyz_dtype(msg: PointCloud2Msg, topic: str, timed: bool = False) -> np.dtype[np.void]:
    """Structured dtype holding x, y, z (and the first per-point time field when ``timed``)
    at their offsets, ``itemsize == point_step``."""
    order: Literal[">", "<"] = ">" if msg.is_bigendian else "<"
    wanted = _XYZ + (TIME_FIELDS if timed else ())
    fields = {}
    needed = 0
    for field in msg.fields:
        base = POINTFIELD_DTYPES.get(int(field.datatype))
        if base is None:
            raise BagError(f"{topic}: field {field.name!r} has unknown datatype {field.datatype}")
        count = max(int(field.count), 1)
        needed = max(needed, int(field.offset) + base.itemsize * count)
        if field.name in wanted and field.name not in fields:
            fields[field.name] = (base.newbyteorder(order), int(field.offset))
    missing = [name for name in _XYZ if name not in fields]
    if missing:
        names = [f.name for f in msg.fields]
        raise BagError(f"{topic}: PointCloud2 has no {'/'.join(missing)} field (fields: {names})")
    if int(msg.point_step) < needed:
        raise BagError(
            f"{topic}: point_step {msg.point_step} is smaller than the {needed} bytes"
            " its fields need"
        )
    names = [*_XYZ, *[n for n in TIME_FIELDS if n in fields][:1]]
    return np.dtype(
        {
            "names": names,
            "formats": [fields[n][0] for n in names],
            "offsets": [fields[n][1] for n in names],
            "itemsize": int(msg.point_step),
        }
    )


def _payload(msg: PointCloud2Msg, topic: str) -> NDArray[np.uint8]:
    """The point bytes without row padding, checked against width/height/steps."""
    width, height = int(msg.width), int(msg.height)
    point_step, row_step = int(msg.point_step), int(msg.row_step)
    data = np.frombuffer(msg.data, dtype=np.uint8)
    row_bytes = width * point_step
    if height > 1 or row_step:
        if row_step < row_bytes:
            raise BagError(
                f"{topic}: row_step {row_step} < width {width} * point_step {point_step}"
            )
    else:
        row_step = row_bytes
    if data.size != height * row_step:
        raise BagError(
            f"{topic}: data has {data.size} bytes, expected height {height} * row_step "
            f"{row_step} = {height * row_step} (width {width}, point_step {point_step})"
        )
    if row_step == row_bytes:
        return data
    return np.ascontiguousarray(data.reshape(height, row_step)[:, :row_bytes]).reshape(-1)


def decode_pointcloud2(msg: PointCloud2Msg, topic: str = "PointCloud2"
                       ) -> tuple[NDArray[np.float64], int]:
    """Return the finite (N, 3) float64 x, y, z of ``msg`` and how many points were dropped.

    Points with a NaN or infinite coordinate (``is_dense = false`` clouds mark
    missing returns that way) are dropped and counted. ``topic`` names the source
    in error messages.
    """
    points, _, dropped = _decode(msg, topic, None)
    return points, dropped


def decode_timed(msg: PointCloud2Msg, stamp_ns: int, topic: str = "PointCloud2"
                 ) -> tuple[NDArray[np.float64], NDArray[np.float64] | None, int]:
    """As :func:`decode_pointcloud2`, plus each point's time in seconds from ``stamp_ns``
    (None when the cloud has no :data:`TIME_FIELDS` field).

    Integer fields are nanoseconds, floating ones seconds (nanoseconds above 1e15, as
    Livox writes them); times that look absolute (over 1e6 s) are made relative to the
    scan stamp. Times further than 2 s from the
    stamp are a unit alte cannot tell: a :class:`BagError` naming the field.
    """
    return _decode(msg, topic, stamp_ns)


def _seconds(raw: NDArray[_Numeric], stamp_ns: int, name: str, topic: str
             ) -> NDArray[np.float64]:
    """Per-point times as float64 seconds relative to the scan stamp (see decode_timed)."""
    if raw.dtype.kind in "iu":
        ns = raw.astype(np.int64)
        if ns.size and int(np.median(ns)) > 10**15:
            ns = ns - stamp_ns
        times = ns * np.float64(1e-9)
    elif raw.size and float(np.median(raw)) > 1e15:  # nanoseconds in a float (Livox)
        times = (raw.astype(np.float64) - stamp_ns) * 1e-9
    else:
        times = raw.astype(np.float64)
        if times.size and float(np.median(times)) > 1e6:
            times = times - stamp_ns * 1e-9
    if times.size and float(np.abs(times).max()) > _MAX_SPAN_S:
        raise BagError(f"{topic}: per-point time field {name!r} spans "
                       f"{float(times.min()):.6g}..{float(times.max()):.6g} s from the scan "
                       "stamp; expected seconds (float) or nanoseconds (integer), relative "
                       "or absolute")
    return times


def _decode(msg: PointCloud2Msg, topic: str,
            stamp_ns: int | None) -> tuple[NDArray[np.float64], NDArray[np.float64] | None, int]:
    dtype = _xyz_dtype(msg, topic, timed=stamp_ns is not None)
    payload = _payload(msg, topic)
    count = int(msg.width) * int(msg.height)
    if count == 0:
        return np.empty((0, 3)), None, 0
    records = np.frombuffer(payload, dtype=dtype, count=count)
    points = np.empty((count, 3), dtype=np.float64)
    for axis, name in enumerate(_XYZ):
        points[:, axis] = records[name]
    names = dtype.names or ()
    times = _seconds(records[names[3]], int(stamp_ns or 0), names[3], topic) \
        if len(names) > 3 else None
    finite = finite_rows(points)
    if finite is None:
        return points, times, 0
    return (points[finite], None if times is None else times[finite],
            int(count - np.count_nonzero(finite)))


def encode_pointcloud2(
    points: NDArray[np.float64],
    stamp_ns: int,
    frame_id: str,
    typestore: Typestore,
    *,
    dtype: CoordType = np.float32,
    extra_fields: Mapping[str, NDArray[np.generic[object]]] | None = None,
) -> MsgType:
    """Build an unorganized little-endian PointCloud2 message (x, y, z, then ``extra_fields``).

    ``dtype`` is the storage type of x, y, z (float32 like real drivers, float64
    for a lossless round trip); each extra field keeps its own numpy dtype.
    """
    pts = np.asarray(points, dtype=np.float64)
    if pts.ndim != 2 or pts.shape[1] != 3:
        raise BagError(f"cloud for frame {frame_id!r} must have shape (N, 3), got {pts.shape}")
    columns: dict[str, NDArray[np.generic[object]]] = {
        name: pts[:, axis] for axis, name in enumerate(_XYZ)}
    formats = {name: np.dtype(dtype).newbyteorder("<") for name in _XYZ}
    for name, values in (extra_fields or {}).items():
        arr = np.asarray(values).reshape(-1)
        if arr.shape[0] != pts.shape[0] or arr.dtype.newbyteorder("=") not in _CODES:
            raise BagError(f"extra field {name!r} must be N={pts.shape[0]} numeric values")
        columns[name] = arr
        formats[name] = arr.dtype.newbyteorder("<")
    record = np.dtype([(name, fmt) for name, fmt in formats.items()])
    table = np.empty(pts.shape[0], dtype=record)
    for name, values in columns.items():
        table[name] = values
    layout = record.fields
    assert layout is not None  # a structured dtype has fields
    types = typestore.types
    fields = [
        types["sensor_msgs/msg/PointField"](
            name=name,
            offset=layout[name][1],
            datatype=_CODES[fmt.newbyteorder("=")],
            count=1,
        )
        for name, fmt in formats.items()
    ]
    return types["sensor_msgs/msg/PointCloud2"](
        header=make_header(stamp_ns, frame_id, typestore),
        height=1,
        width=pts.shape[0],
        fields=fields,
        is_bigendian=False,
        point_step=record.itemsize,
        row_step=record.itemsize * pts.shape[0],
        data=np.frombuffer(table.tobytes(), dtype=np.uint8),
        is_dense=bool(np.isfinite(pts).all()),
    )


def make_time(stamp_ns: int, typestore: Typestore) -> MsgType:
    """A ``builtin_interfaces/msg/Time`` for ``stamp_ns``."""
    sec, nanosec = divmod(int(stamp_ns), 1_000_000_000)
    return typestore.types["builtin_interfaces/msg/Time"](sec=sec, nanosec=nanosec)


def make_header(stamp_ns: int, frame_id: str, typestore: Typestore) -> MsgType:
    """A ``std_msgs/msg/Header`` for ``stamp_ns``."""
    return typestore.types["std_msgs/msg/Header"](stamp=make_time(stamp_ns, typestore),
                                                  frame_id=frame_id)
