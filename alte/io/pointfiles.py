"""Point files in and out: PCD, PLY, LAS/LAZ, ``.npz`` and plain ``x y z`` text.

Every reader returns an (N, 3) float64 array. PCD is parsed here (ascii, binary and
binary_compressed, any field types) because open3d reads 8-byte PCD fields as zeros;
PLY goes through open3d, LAS/LAZ through laspy (scaled coordinates). Rows with a
non-finite coordinate (organised PCDs mark missing returns with NaN) are dropped;
:func:`read_points_info` says how many. A file left with no points is an error.
Writers are atomic and refuse to overwrite unless asked; LAS/LAZ store coordinates
as integers, quantised to 0.1 mm. Georeferenced clouds (UTM, 1e6-1e7 m) should be
shifted by :func:`local_origin` before centimetre cells are computed.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numba
import numpy as np
import pandas as pd

from alte.errors import ParameterError, PointFileError
from alte.fsutil import atomic_path

__all__ = [
    "READ_SUFFIXES",
    "WRITE_SUFFIXES",
    "PointFileInfo",
    "local_origin",
    "read_points",
    "read_points_info",
    "write_points",
]

_TEXT = (".xyz", ".txt", ".dat")
READ_SUFFIXES = (".pcd", ".ply", ".las", ".laz", ".npz", *_TEXT, *(s + ".bz2" for s in _TEXT))
WRITE_SUFFIXES = (".pcd", ".ply", ".las", ".laz", ".npz", *_TEXT)
_LAS_SCALE = 1e-4
_PCD_TYPES = {"F": "f", "U": "u", "I": "i"}


@dataclass(frozen=True)
class PointFileInfo:
    """Points read from a file and how many rows were dropped as non-finite."""

    points: np.ndarray
    rows: int
    nonfinite: int


def _suffix(path: Path) -> str:
    suffixes = [s.lower() for s in path.suffixes[-2:]]
    if len(suffixes) == 2 and suffixes[1] == ".bz2":
        return "".join(suffixes)
    return suffixes[-1] if suffixes else ""


# ------------------------------------------------------------------------------ PCD


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


def _read_pcd(path: Path) -> np.ndarray:
    """Vectorized PCD reader for the ascii, binary and binary_compressed encodings."""
    raw = path.read_bytes()
    header, offset = _pcd_header(raw, path)
    dtype = _pcd_dtype(header, path)
    try:
        count = int(header.get("POINTS", header.get("WIDTH", ["0"]))[0])
    except ValueError as err:
        raise PointFileError(f"{path}: bad POINTS line {header.get('POINTS')}") from err
    kind = header["DATA"][0].lower() if header["DATA"] else ""
    fields = [name.rsplit("_", 1)[0] for name in dtype.names]
    if kind == "ascii":
        counts = [dtype[name].shape[0] for name in dtype.names]
        starts = np.cumsum([0, *counts[:-1]])
        table = _read_table(path, offset=offset)
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
    columns = [data[dtype.names[fields.index(c)]][:, 0] for c in "xyz"]
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
    for name in dtype.names:  # one contiguous column per field
        width = dtype[name].itemsize * count
        out[name] = body[start : start + width].view(dtype[name].base).reshape(count, -1)
        start += width
    return out


# ------------------------------------------------------------------------------ others


def _read_table(path: Path, offset: int = 0) -> pd.DataFrame:
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


def _read_text(path: Path) -> np.ndarray:
    table = _read_table(path)
    if table.shape[1] < 3:
        raise PointFileError(f"{path}: {table.shape[1]} column(s); expected x y z per line")
    return table.iloc[:, :3].to_numpy(np.float64)


def _read_ply(path: Path) -> np.ndarray:
    import open3d as o3d

    with o3d.utility.VerbosityContextManager(o3d.utility.VerbosityLevel.Error):
        cloud = o3d.io.read_point_cloud(str(path), format="ply")
    return np.asarray(cloud.points, dtype=np.float64).copy()


def _read_las(path: Path) -> np.ndarray:
    import laspy

    las = laspy.read(path)
    return np.column_stack([np.asarray(las.x), np.asarray(las.y), np.asarray(las.z)])


def _read_npz(path: Path) -> np.ndarray:
    with np.load(path, allow_pickle=False) as archive:
        if "points" not in archive.files:
            raise PointFileError(f"{path}: no 'points' array (has {archive.files})")
        return np.asarray(archive["points"], dtype=np.float64)


_READERS = {".pcd": _read_pcd, ".ply": _read_ply, ".las": _read_las, ".laz": _read_las}
_READERS |= {".npz": _read_npz} | {s: _read_text for s in READ_SUFFIXES if s.startswith(_TEXT)}


def read_points_info(path: str | os.PathLike[str]) -> PointFileInfo:
    """Read a point file; return its finite points and how many rows were dropped."""
    path = Path(path)
    reader = _READERS.get(_suffix(path))
    if reader is None:
        raise PointFileError(f"{path}: unknown point file type; supported: {READ_SUFFIXES}")
    if not path.is_file():
        raise PointFileError(f"{path}: no such point file")
    try:
        points = reader(path)
    except PointFileError:
        raise
    except Exception as err:  # any library failure: unreadable file
        raise PointFileError(
            f"{path}: unreadable point file ({type(err).__name__}: {err})"
        ) from err
    if points.ndim != 2 or points.shape[1] != 3:
        raise PointFileError(f"{path}: points have shape {points.shape}, expected (N, 3)")
    if len(points) == 0:
        raise PointFileError(f"{path}: no points (empty or unreadable file)")
    finite = np.isfinite(points).all(axis=1)
    if not finite.any():
        raise PointFileError(f"{path}: no finite points ({len(points)} rows)")
    kept = np.ascontiguousarray(points[finite], dtype=np.float64)
    return PointFileInfo(kept, len(points), int(len(points) - len(kept)))


def read_points(path: str | os.PathLike[str]) -> np.ndarray:
    """(N, 3) float64 points of a PCD, PLY, LAS/LAZ, npz or xyz file; non-finite rows dropped."""
    return read_points_info(path).points


# ------------------------------------------------------------------------------ writers


def _write_pcd(tmp: Path, points: np.ndarray) -> None:
    header = (
        "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z\n"
        "SIZE 8 8 8\nTYPE F F F\nCOUNT 1 1 1\n"
        f"WIDTH {len(points)}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\n"
        f"POINTS {len(points)}\nDATA binary\n"
    )
    tmp.write_bytes(header.encode("ascii") + points.astype("<f8").tobytes())


def _write_ply(tmp: Path, points: np.ndarray) -> None:
    header = (
        "ply\nformat binary_little_endian 1.0\ncomment written by alte\n"
        f"element vertex {len(points)}\n"
        "property double x\nproperty double y\nproperty double z\nend_header\n"
    )
    tmp.write_bytes(header.encode("ascii") + points.astype("<f8").tobytes())


def _write_npz(tmp: Path, points: np.ndarray) -> None:
    with open(tmp, "wb") as fh:  # a handle stops numpy appending ".npz"
        np.savez_compressed(fh, points=points)


def _write_text(tmp: Path, points: np.ndarray) -> None:
    # pandas prints the shortest repr that round-trips each float64 exactly
    pd.DataFrame(points).to_csv(tmp, sep=" ", header=False, index=False)


def _write_las(tmp: Path, points: np.ndarray, compress: bool) -> None:
    import laspy

    header = laspy.LasHeader(point_format=0, version="1.2")
    header.offsets = local_origin(points)
    header.scales = np.full(3, _LAS_SCALE)
    reach = np.abs(points - header.offsets).max() / _LAS_SCALE
    if reach >= 2**31 - 1:
        raise PointFileError(f"{tmp}: cloud spans too far for LAS at {_LAS_SCALE} m resolution")
    las = laspy.LasData(header)
    las.x, las.y, las.z = points[:, 0], points[:, 1], points[:, 2]
    with open(tmp, "wb") as fh:
        las.write(fh, do_compress=compress)


_WRITERS = {".pcd": _write_pcd, ".ply": _write_ply, ".npz": _write_npz}
_WRITERS |= {s: _write_text for s in _TEXT}
_WRITERS |= {
    ".las": lambda t, p: _write_las(t, p, False),
    ".laz": lambda t, p: _write_las(t, p, True),
}


def write_points(path: str | os.PathLike[str], points: np.ndarray, overwrite: bool = False) -> Path:
    """Write (N, 3) points atomically as PCD (binary, float64), PLY, npz, xyz text or LAS/LAZ."""
    path = Path(path)
    writer = _WRITERS.get(_suffix(path))
    if writer is None:
        raise PointFileError(f"{path}: cannot write this type; supported: {WRITE_SUFFIXES}")
    arr = np.asarray(points, dtype=np.float64)
    if arr.ndim != 2 or arr.shape[1] != 3 or len(arr) == 0:
        raise PointFileError(f"{path}: points must have shape (N, 3) with N > 0, got {arr.shape}")
    if not np.isfinite(arr).all():
        raise PointFileError(f"{path}: refusing to write non-finite coordinates")
    if path.exists() and not overwrite:
        raise PointFileError(f"{path} already exists; pass overwrite=True to replace it")
    with atomic_path(path, overwrite=overwrite) as tmp:
        writer(tmp, np.ascontiguousarray(arr))
    return path


def local_origin(points: np.ndarray, quantum: float = 1000.0) -> np.ndarray:
    """Bounding-box centre rounded to ``quantum`` metres: subtract it from georeferenced
    clouds so that local coordinates (and centimetre cells) stay exact in float64.
    Clouds already near the origin get a zero origin."""
    if not np.isfinite(quantum) or quantum <= 0:
        raise ParameterError(f"quantum={quantum!r} must be a positive number of metres")
    arr = np.asarray(points, dtype=np.float64)
    if arr.ndim != 2 or arr.shape[1] != 3 or len(arr) == 0:
        raise ParameterError(f"points must have shape (N, 3) with N > 0, got {arr.shape}")
    if not np.isfinite(arr).all():
        raise ParameterError("points hold non-finite coordinates; cannot choose an origin")
    centre = 0.5 * (arr.min(axis=0) + arr.max(axis=0))
    return np.round(centre / quantum) * quantum + 0.0  # + 0.0 turns -0.0 into 0.0
