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

import datetime
import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from alte.errors import ParameterError, PointFileError
from alte.fsutil import atomic_path
from alte.io.pcd import read_pcd, read_table, write_pcd

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


def _read_text(path: Path) -> np.ndarray:
    table = read_table(path)
    if table.shape[1] < 3:
        raise PointFileError(f"{path}: {table.shape[1]} column(s); expected x y z per line")
    return table.iloc[:, :3].to_numpy(np.float64)


_PLY_SIZES = {"char": 1, "int8": 1, "uchar": 1, "uint8": 1, "short": 2, "int16": 2,
              "ushort": 2, "uint16": 2, "int": 4, "int32": 4, "uint": 4, "uint32": 4,
              "float": 4, "float32": 4, "double": 8, "float64": 8}


def _ply_layout(path: Path) -> tuple[str, int, int]:
    """(format, header bytes, minimum body: bytes if binary, rows if ascii) of a PLY file."""
    with open(path, "rb") as fh:
        head = fh.read(65536)
    end = head.find(b"end_header")
    if not head.startswith(b"ply") or end < 0:
        raise PointFileError(f"{path}: not a PLY file (no 'ply' ... 'end_header' header)")
    fmt, rows, size, count = "", 0, 0, 0
    for line in head[:end].decode("ascii", "replace").splitlines():
        word = line.split()
        if word[:1] == ["format"] and len(word) > 1:
            fmt = word[1]
        elif word[:1] == ["element"] and len(word) > 2:
            count = int(word[2])
            rows += count
        elif word[:1] == ["property"] and len(word) > 2:  # a list counts its length field
            size += count * _PLY_SIZES.get(word[2] if word[1] == "list" else word[1], 0)
    body_start = head.index(b"\n", end) + 1
    return fmt, body_start, rows if fmt == "ascii" else size


def _check_ply_complete(path: Path) -> None:
    """Raise when the body is shorter than the header announces (open3d only warns)."""
    fmt, start, need = _ply_layout(path)
    if fmt == "ascii":
        with open(path, "rb") as fh:
            fh.seek(start)
            have = sum(1 for line in fh if line.strip())
    else:
        have = path.stat().st_size - start
    if have < need:
        unit = "rows" if fmt == "ascii" else "bytes"
        raise PointFileError(
            f"{path}: truncated PLY ({have} of {need} {unit} the header announces)"
        )


def _read_ply(path: Path) -> np.ndarray:
    import open3d as o3d

    _check_ply_complete(path)

    with o3d.utility.VerbosityContextManager(o3d.utility.VerbosityLevel.Error):
        cloud = o3d.io.read_point_cloud(path, format="ply")
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


_READERS = {".pcd": read_pcd, ".ply": _read_ply, ".las": _read_las, ".laz": _read_las}
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


#: The header's creation day: fixed, as numpy fixes the dates inside ``.npz`` files, so the
#: same cloud gives the same bytes on any day.
_LAS_DATE = datetime.date(1980, 1, 1)


def _write_las(tmp: Path, points: np.ndarray, compress: bool) -> None:
    import laspy

    header = laspy.LasHeader(point_format=0, version="1.2")
    header.creation_date = _LAS_DATE
    header.offsets = local_origin(points)
    header.scales = np.full(3, _LAS_SCALE)
    reach = np.abs(points - header.offsets).max() / _LAS_SCALE
    if reach >= 2**31 - 1:
        raise PointFileError(f"{tmp}: cloud spans too far for LAS at {_LAS_SCALE} m resolution")
    las = laspy.LasData(header)
    las.x, las.y, las.z = points[:, 0], points[:, 1], points[:, 2]
    with open(tmp, "wb") as fh:
        las.write(fh, do_compress=compress)


_WRITERS: dict[str, Callable[[Path, np.ndarray], None]] = {
    ".pcd": write_pcd, ".ply": _write_ply, ".npz": _write_npz}
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
    origin: np.ndarray = np.round(centre / quantum) * quantum + 0.0  # + 0.0: -0.0 -> 0.0
    return origin
