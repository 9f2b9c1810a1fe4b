"""PCD files: a vectorized reader (ascii, binary, binary_compressed; any field types, every
field kept) and a binary writer (float64 x y z plus the other fields).

Parsed here rather than with open3d, which reads 8-byte PCD fields as zeros; the LZF
decompression of binary_compressed bodies is compiled with numba (:mod:`~alte.io.points.lzf`).
The reader is as strict as PCL's: a header whose ``WIDTH x HEIGHT`` differs from
``POINTS``, or a body with fewer rows (or bytes) than the header announces, is refused
with the counts, never read short.
Packed colours (``rgb``/``rgba``, PCL's float- or uint32-packed 0xAARRGGBB) become a
``colors`` (N, 3) uint8 field and are packed again on writing.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, TypeAlias

import numpy as np
from numpy.typing import NDArray

from alte.errors import PointFileError

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["Fields", "PcdHeader", "pack_rgb", "pcd_header", "read_pcd", "read_pcd_table",
           "read_table", "unpack_rgb", "write_pcd"]

#: A point file's per-point values by name (N rows each), each array of its own dtype.
Fields: TypeAlias = "dict[str, NDArray[np.generic[object]]]"

_PCD_TYPES = {"F": "f", "U": "u", "I": "i"}
_TYPE_LETTER = {"f": "F", "u": "U", "i": "I", "b": "U"}
_RGB = ("rgb", "rgba")


@dataclass(frozen=True)
class PcdHeader:
    """A PCD header: ``fields`` (name, size, type letter, count), ``width`` x ``height``
    (organised when height > 1), ``points``, ``encoding`` and where the body starts."""

    version: str
    fields: tuple[tuple[str, int, str, int], ...]
    width: int
    height: int
    points: int
    viewpoint: tuple[float, ...]
    encoding: str
    offset: int

    @property
    def dtype(self) -> np.dtype[np.void]:
        """One row of the body (fields suffixed with their index: names may repeat)."""
        return np.dtype([(f"{name}_{i}", f"<{_PCD_TYPES[t]}{size}", (count,))
                         for i, (name, size, t, count) in enumerate(self.fields)])


def _lines(raw: bytes, path: Path) -> tuple[dict[str, list[str]], int]:
    """Header fields (upper-case keys) and the offset of the data section."""
    header: dict[str, list[str]] = {}
    offset = 0
    while offset < len(raw):
        end = raw.find(b"\n", offset)
        end = len(raw) if end < 0 else end
        words = raw[offset:end].decode("ascii", "replace").split()
        offset = end + 1
        if words and not words[0].startswith("#"):
            header[words[0].upper()] = words[1:]
            if words[0].upper() == "DATA":
                return header, offset
    raise PointFileError(f"{path}: not a PCD file (no DATA line in the header)")


def _fields(header: dict[str, list[str]], path: Path) -> tuple[tuple[str, int, str, int], ...]:
    names = header.get("FIELDS", [])
    sizes, types = header.get("SIZE", []), header.get("TYPE", [])
    counts = header.get("COUNT", ["1"] * len(names))
    if not {"x", "y", "z"} <= set(names):
        raise PointFileError(f"{path}: PCD fields {names} lack x, y and z")
    if not len(names) == len(sizes) == len(types) == len(counts):
        raise PointFileError(f"{path}: PCD header FIELDS/SIZE/TYPE/COUNT lengths differ")
    try:
        out = tuple((n, int(s), t.upper(), int(c))
                    for n, s, t, c in zip(names, sizes, types, counts, strict=True))
        np.dtype([(f"f{i}", f"<{_PCD_TYPES[t]}{s}") for i, (_, s, t, _) in enumerate(out)])
    except (KeyError, TypeError, ValueError) as err:
        raise PointFileError(f"{path}: bad PCD field types {types} / sizes {sizes}") from err
    return out


def _integer(header: dict[str, list[str]], key: str, path: Path, default: int | None) -> int:
    words = header.get(key)
    if not words:
        if default is None:
            raise PointFileError(f"{path}: PCD header has no {key} line")
        return default
    try:
        return int(words[0])
    except ValueError as err:
        raise PointFileError(f"{path}: bad {key} line {' '.join(words)!r}") from err


def pcd_header(raw: bytes, path: Path) -> PcdHeader:
    """Parse and check the header at the start of ``raw`` (``WIDTH x HEIGHT == POINTS``)."""
    header, offset = _lines(raw, path)
    fields = _fields(header, path)
    width = _integer(header, "WIDTH", path, None if "POINTS" not in header else -1)
    height = _integer(header, "HEIGHT", path, 1)
    points = _integer(header, "POINTS", path, width * height)
    if width < 0:
        width = points
    if width * height != points:
        raise PointFileError(f"{path}: PCD header says WIDTH {width} x HEIGHT {height} = "
                             f"{width * height} points but POINTS {points}")
    encoding = header["DATA"][0].lower() if header["DATA"] else ""
    viewpoint = tuple(float(v) for v in header.get("VIEWPOINT", ["0", "0", "0", "1", "0", "0",
                                                                 "0"]))
    version = " ".join(header.get("VERSION", ["?"]))
    return PcdHeader(version, fields, width, height, points, viewpoint, encoding, offset)


def read_table(path: Path, offset: int = 0) -> pd.DataFrame:
    """Whitespace-separated numbers (pandas' C parser), optionally after a byte offset."""
    import pandas as pd  # on first use: pandas is ~80 MB resident

    with open(path, "rb") as fh:
        fh.seek(offset)
        return pd.read_csv(
            fh,
            sep=r"\s+",
            header=None,
            comment="#",
            compression="bz2" if path.suffix.lower() == ".bz2" else None,
            dtype=np.float64,
            engine="c",
            on_bad_lines="error",
        )


def _last_row_width(raw: bytes, offset: int) -> int:
    """Number of values on the body's last non-empty line (a half-written row has fewer)."""
    body = raw[offset:].rstrip()
    return len(body[body.rfind(b"\n") + 1:].split()) if body else 0


def _ascii(raw: bytes, head: PcdHeader, path: Path) -> NDArray[np.void]:
    dtype = head.dtype
    import pandas as pd

    width = sum(count for *_, count in head.fields)
    try:
        table = read_table(path, offset=head.offset) if head.points else None
    except pd.errors.EmptyDataError:
        table = None
    rows = 0 if table is None else len(table)
    if rows < head.points:
        raise PointFileError(f"{path}: truncated ascii PCD: {rows} of the {head.points} rows "
                             "its header announces")
    assert table is not None or head.points == 0
    if table is not None and table.shape[1] != width:
        raise PointFileError(f"{path}: {table.shape[1]} ascii columns, header says {width}")
    if table is not None and _last_row_width(raw, head.offset) != width:
        raise PointFileError(f"{path}: truncated ascii PCD: its last row has "
                             f"{_last_row_width(raw, head.offset)} of {width} values")
    values = np.empty((head.points, width)) if table is None else \
        table.iloc[: head.points].to_numpy(np.float64)
    out = np.empty(head.points, dtype)
    start = 0
    for name in dtype.names or ():
        count = dtype[name].shape[0]
        out[name] = values[:, start:start + count]
        start += count
    return out


def _binary(raw: bytes, head: PcdHeader, path: Path) -> NDArray[np.void]:
    need, have = head.points * head.dtype.itemsize, len(raw) - head.offset
    if have < need:
        raise PointFileError(f"{path}: truncated binary PCD: {have} of the {need} bytes "
                             f"({have // head.dtype.itemsize} of {head.points} rows) its "
                             "header announces")
    return np.frombuffer(raw, head.dtype, count=head.points, offset=head.offset)


def _compressed(raw: bytes, head: PcdHeader, path: Path) -> NDArray[np.void]:
    """Decompress a binary_compressed body (field-major) into a structured array."""
    blob, dtype, count = raw[head.offset:], head.dtype, head.points
    if len(blob) < 8:
        raise PointFileError(f"{path}: truncated binary_compressed PCD: {len(blob)} bytes "
                             "after the header, less than its 8-byte sizes")
    packed, size = (int(v) for v in np.frombuffer(blob, "<u4", 2))
    if size != count * dtype.itemsize:
        raise PointFileError(f"{path}: binary_compressed sizes do not match the header: the "
                             f"body unpacks to {size} bytes, {count} rows need "
                             f"{count * dtype.itemsize}")
    if packed > len(blob) - 8:
        raise PointFileError(f"{path}: truncated binary_compressed PCD: {len(blob) - 8} of the "
                             f"{packed} compressed bytes ({count} rows) it announces")
    from alte.io.points.lzf import lzf_decompress  # numba: compressed bodies only

    body = lzf_decompress(np.frombuffer(blob, np.uint8, packed, 8), size)
    if body.size != size:
        raise PointFileError(f"{path}: corrupt LZF data in binary_compressed PCD")
    out = np.empty(count, dtype)
    start = 0
    for name in dtype.names or ():  # one contiguous column per field
        width = dtype[name].itemsize * count
        out[name] = body[start : start + width].view(dtype[name].base).reshape(count, -1)
        start += width
    return out


def unpack_rgb(values: NDArray[np.generic[object]]) -> NDArray[np.uint8]:
    """PCL's packed colour (float32 or uint32 bits 0xAARRGGBB) -> (N, 3) uint8 RGB."""
    bits = np.ascontiguousarray(values).view(np.uint32) if values.dtype.itemsize == 4 \
        else np.asarray(values, dtype=np.uint32)
    return np.column_stack([(bits >> 16) & 255, (bits >> 8) & 255, bits & 255]).astype(np.uint8)


def pack_rgb(colors: NDArray[np.generic[object]]) -> NDArray[np.float32]:
    """(N, 3) uint8 RGB -> PCL's float32-packed ``rgb``."""
    c = np.asarray(colors, dtype=np.uint32)
    return ((c[:, 0] << 16) | (c[:, 1] << 8) | c[:, 2]).astype(np.uint32).view(np.float32)


def read_pcd_table(path: Path) -> tuple[PcdHeader, NDArray[np.float64], Fields]:
    """Header, (N, 3) float64 x y z and every other field ((N,) or (N, count); packed
    colours as ``colors`` (N, 3) uint8) of a PCD file, every row kept (NaN included)."""
    raw = path.read_bytes()
    head = pcd_header(raw, path)
    readers = {"ascii": _ascii, "binary": _binary, "binary_compressed": _compressed}
    if head.encoding not in readers:
        raise PointFileError(f"{path}: unknown PCD DATA encoding {head.encoding!r}")
    data = readers[head.encoding](raw, head, path)
    names = data.dtype.names or ()
    bare = [name.rsplit("_", 1)[0] for name in names]
    points = np.column_stack([data[names[bare.index(c)]][:, 0] for c in "xyz"]
                             ).astype(np.float64) if len(data) else np.empty((0, 3))
    fields: Fields = {}
    for name, field in zip(bare, names, strict=True):
        if name in {"x", "y", "z", "_"} or name in fields:
            continue  # padding ("_") and repeated names carry nothing a user named
        column = np.asarray(data[field])
        column = column[:, 0] if column.shape[1] == 1 else column
        if name in _RGB and column.ndim == 1:
            fields["colors"] = unpack_rgb(column)
        else:
            fields[name] = column.copy()
    return head, points, fields


def read_pcd(path: Path) -> NDArray[np.float64]:
    """(N, 3) float64 x y z of a PCD file (ascii, binary or binary_compressed)."""
    return read_pcd_table(path)[1]


def write_pcd(tmp: Path, points: NDArray[np.float64], fields: Fields | None = None) -> None:
    """Binary PCD: float64 x y z, then each field with its own type (``colors`` packed
    into a float32 ``rgb``)."""
    columns: list[tuple[str, NDArray[np.generic[object]]]] = [
        ("x", points[:, 0]), ("y", points[:, 1]), ("z", points[:, 2])]
    for name, values in (fields or {}).items():
        columns.append(("rgb", pack_rgb(values)) if name == "colors"
                       else (name, np.asarray(values)))
    dtype = np.dtype([(f"c{i}", v.dtype.newbyteorder("<"), v.shape[1:])
                      for i, (_, v) in enumerate(columns)])
    body = np.empty(len(points), dtype)
    for i, (_, values) in enumerate(columns):
        body[f"c{i}"] = values
    specs = [(name, v.dtype, int(np.prod(v.shape[1:], dtype=int))) for name, v in columns]
    header = (
        "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\n"
        f"FIELDS {' '.join(n for n, _, _ in specs)}\n"
        f"SIZE {' '.join(str(t.itemsize) for _, t, _ in specs)}\n"
        f"TYPE {' '.join(_TYPE_LETTER[t.kind] for _, t, _ in specs)}\n"
        f"COUNT {' '.join(str(c) for _, _, c in specs)}\n"
        f"WIDTH {len(points)}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\n"
        f"POINTS {len(points)}\nDATA binary\n"
    )
    tmp.write_bytes(header.encode("ascii") + body.tobytes())
