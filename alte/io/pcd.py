"""PCD files: a vectorized reader (ascii, binary, binary_compressed; any field types)
and a binary float64 writer.

Parsed here rather than with open3d, which reads 8-byte PCD fields as zeros; the LZF
decompression of binary_compressed bodies is compiled with numba.
"""

from __future__ import annotations

from pathlib import Path

import numba
import numpy as np
import pandas as pd

from alte.errors import PointFileError

__all__ = ["read_pcd", "read_table", "write_pcd"]

_PCD_TYPES = {"F": "f", "U": "u", "I": "i"}


@numba.njit(cache=True)
def _lzf_decompress(src: np.ndarray, size: int) -> np.ndarray:  # pragma: no cover - compiled
    """liblzf decompression (PCD binary_compressed); empty result on corrupt input."""
    out = np.empty(size, np.uint8)
    ip, op = 0, 0
    while ip < src.size:
        ctrl = int(src[ip])
        ip += 1
        if ctrl < 32:  # literal run of ctrl + 1 bytes
            n = ctrl + 1
            if ip + n > src.size or op + n > size:
                return out[:0]
            out[op : op + n] = src[ip : ip + n]
            ip += n
            op += n
            continue
        n = ctrl >> 5  # back reference
        if n == 7:
            if ip >= src.size:
                return out[:0]
            n += int(src[ip])
            ip += 1
        if ip >= src.size:
            return out[:0]
        ref = op - ((ctrl & 0x1F) << 8) - 1 - int(src[ip])
        ip += 1
        n += 2
        if ref < 0 or op + n > size:
            return out[:0]
        for k in range(n):  # byte by byte: the source may overlap the output
            out[op + k] = out[ref + k]
        op += n
    return out[:op]


def _pcd_header(raw: bytes, path: Path) -> tuple[dict[str, list[str]], int]:
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


def _pcd_dtype(header: dict[str, list[str]], path: Path) -> np.dtype:
    fields = header.get("FIELDS", [])
    sizes, types = header.get("SIZE", []), header.get("TYPE", [])
    counts = header.get("COUNT", ["1"] * len(fields))
    if not {"x", "y", "z"} <= set(fields):
        raise PointFileError(f"{path}: PCD fields {fields} lack x, y and z")
    if not len(fields) == len(sizes) == len(types) == len(counts):
        raise PointFileError(f"{path}: PCD header FIELDS/SIZE/TYPE/COUNT lengths differ")
    try:
        parts = [
            (f"{name}_{i}", f"<{_PCD_TYPES[t.upper()]}{int(s)}", (int(c),))
            for i, (name, s, t, c) in enumerate(zip(fields, sizes, types, counts, strict=True))
        ]
        return np.dtype(parts)
    except (KeyError, TypeError, ValueError) as err:
        raise PointFileError(f"{path}: bad PCD field types {types} / sizes {sizes}") from err


def read_pcd(path: Path) -> np.ndarray:
    """Vectorized PCD reader for the ascii, binary and binary_compressed encodings."""
    raw = path.read_bytes()
    header, offset = _pcd_header(raw, path)
    dtype = _pcd_dtype(header, path)
    names = dtype.names
    assert names is not None  # _pcd_dtype builds a structured dtype
    try:
        count = int(header.get("POINTS", header.get("WIDTH", ["0"]))[0])
    except ValueError as err:
        raise PointFileError(f"{path}: bad POINTS line {header.get('POINTS')}") from err
    kind = header["DATA"][0].lower() if header["DATA"] else ""
    fields = [name.rsplit("_", 1)[0] for name in names]
    if kind == "ascii":
        counts = [dtype[name].shape[0] for name in names]
        starts = np.cumsum([0, *counts[:-1]])
        table = read_table(path, offset=offset)
        if table.shape[1] != sum(counts):
            raise PointFileError(
                f"{path}: {table.shape[1]} ascii columns, header says {sum(counts)}"
            )
        return table.iloc[:count, [starts[fields.index(c)] for c in "xyz"]].to_numpy(np.float64)
    if kind == "binary":
        data = np.frombuffer(raw, dtype, count=count, offset=offset)
    elif kind == "binary_compressed":
        data = _pcd_decompress(raw[offset:], dtype, count, path)
    else:
        raise PointFileError(f"{path}: unknown PCD DATA encoding {kind!r}")
    columns = [data[names[fields.index(c)]][:, 0] for c in "xyz"]
    return np.column_stack(columns).astype(np.float64)


def _pcd_decompress(blob: bytes, dtype: np.dtype, count: int, path: Path) -> np.ndarray:
    """Decompress a binary_compressed body (field-major) into a structured array."""
    if len(blob) < 8:
        raise PointFileError(f"{path}: truncated binary_compressed PCD")
    packed, size = (int(v) for v in np.frombuffer(blob, "<u4", 2))
    if size != count * dtype.itemsize or packed > len(blob) - 8:
        raise PointFileError(f"{path}: binary_compressed sizes do not match the header")
    body = _lzf_decompress(np.frombuffer(blob, np.uint8, packed, 8), size)
    if body.size != size:
        raise PointFileError(f"{path}: corrupt LZF data in binary_compressed PCD")
    out = np.empty(count, dtype)
    start = 0
    assert dtype.names is not None  # _pcd_dtype builds a structured dtype
    for name in dtype.names:  # one contiguous column per field
        width = dtype[name].itemsize * count
        out[name] = body[start : start + width].view(dtype[name].base).reshape(count, -1)
        start += width
    return out




def read_table(path: Path, offset: int = 0) -> pd.DataFrame:
    """Whitespace-separated numbers (pandas' C parser), optionally after a byte offset."""
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


def write_pcd(tmp: Path, points: np.ndarray) -> None:
    header = (
        "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z\n"
        "SIZE 8 8 8\nTYPE F F F\nCOUNT 1 1 1\n"
        f"WIDTH {len(points)}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\n"
        f"POINTS {len(points)}\nDATA binary\n"
    )
    tmp.write_bytes(header.encode("ascii") + points.astype("<f8").tobytes())
