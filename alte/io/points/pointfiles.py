"""Point files in and out: PCD, PLY, LAS/LAZ, ``.npz`` and plain ``x y z`` text.

Every reader gives (N, 3) float64 coordinates and the file's other per-point fields
(intensity, colours, labels, ...; :mod:`alte.io.points.pointformats`, :mod:`alte.io.points.pcd`).
PCD is parsed here (ascii, binary and binary_compressed, any field types) because open3d
reads 8-byte PCD fields as zeros; PLY goes through open3d, LAS/LAZ through laspy (scaled
coordinates). Rows with a non-finite coordinate (organised PCDs mark missing returns
with NaN) are dropped; :func:`read_points_info` says how many. A file left with no
points is an error, and so is a body shorter than its header announces. Writers are
atomic, refuse to overwrite unless asked, and keep the fields the format can hold
(:func:`alte.io.points.pointformats.storable`); LAS/LAZ store coordinates as integers,
quantised to 0.1 mm. Georeferenced clouds (UTM, 1e6-1e7 m) should be shifted by
:func:`local_origin` before centimetre cells are computed.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from alte.errors import PointFileError
from alte.fsutil import atomic_path
from alte.io.points.pcd import read_pcd_table, write_pcd
from alte.io.points.pointformats import (
    Fields,
    FileAbout,
    local_origin,
    read_las,
    read_npz,
    read_ply,
    read_text,
    storable,
    write_las,
    write_npz,
    write_ply,
    write_text,
)

__all__ = [
    "READ_SUFFIXES",
    "WRITE_SUFFIXES",
    "PointFileInfo",
    "PointSummary",
    "PointTable",
    "describe_points",
    "local_origin",
    "read_point_table",
    "read_points",
    "read_points_info",
    "storable",
    "write_points",
]

_TEXT = (".xyz", ".txt", ".dat")
READ_SUFFIXES = (".pcd", ".ply", ".las", ".laz", ".npz", *_TEXT, *(s + ".bz2" for s in _TEXT))
WRITE_SUFFIXES = (".pcd", ".ply", ".las", ".laz", ".npz", *_TEXT)


@dataclass(frozen=True)
class PointTable:
    """Every row of a point file: ``points`` (N, 3, non-finite rows included), the other
    per-point ``fields`` and ``about``: what the file says of itself (format, encoding,
    its fields and their types, ...)."""

    points: NDArray[np.float64]
    fields: Fields
    about: FileAbout


@dataclass(frozen=True)
class PointFileInfo:
    """Points read from a file (finite rows), how many rows it had and how many were dropped
    as non-finite, and the kept rows' other fields."""

    points: NDArray[np.float64]
    rows: int
    nonfinite: int
    fields: Fields = field(default_factory=dict)


class PointSummary(FileAbout):
    """What a point file holds (``alte info FILE``; its ``--json`` object): the file's own
    description, its rows, finite points and non-finite rows (those with NaN apart), the
    finite points' bounds ``[[xmin, ymin, zmin], [xmax, ymax, zmax]]`` (None without any)
    and each numeric field's ``[min, max]``."""

    file: str
    rows: int
    points: int
    nonfinite: int
    nan: int
    bounds: list[list[float]] | None
    field_ranges: dict[str, list[float]]


def _suffix(path: Path) -> str:
    suffixes = [s.lower() for s in path.suffixes[-2:]]
    if len(suffixes) == 2 and suffixes[1] == ".bz2":
        return "".join(suffixes)
    return suffixes[-1] if suffixes else ""


def _read_pcd(path: Path) -> tuple[NDArray[np.float64], Fields, FileAbout]:
    head, points, fields = read_pcd_table(path)
    about: FileAbout = {"format": f"PCD {head.version}", "encoding": head.encoding,
             "fields": [{"name": n, "type": f"{t}{s}", "count": c} for n, s, t, c in head.fields],
             "width": head.width, "height": head.height, "viewpoint": list(head.viewpoint)}
    return points, fields, about


_READERS: dict[str, Callable[[Path], tuple[NDArray[np.float64], Fields, FileAbout]]] = {
    ".pcd": _read_pcd, ".ply": read_ply, ".las": read_las, ".laz": read_las, ".npz": read_npz}
_READERS |= {s: read_text for s in READ_SUFFIXES if s.startswith(_TEXT)}


def read_point_table(path: str | os.PathLike[str]) -> PointTable:
    """Every row and field of a point file (:class:`PointTable`); errors name the file."""
    path = Path(path)
    reader = _READERS.get(_suffix(path))
    if reader is None:
        raise PointFileError(f"{path}: unknown point file type; supported: {READ_SUFFIXES}")
    if not path.is_file():
        raise PointFileError(f"{path}: no such point file")
    try:
        points, fields, about = reader(path)
    except PointFileError:
        raise
    except Exception as err:  # any library failure: unreadable file
        raise PointFileError(
            f"{path}: unreadable point file ({type(err).__name__}: {err})"
        ) from err
    if points.ndim != 2 or points.shape[1] != 3:
        raise PointFileError(f"{path}: points have shape {points.shape}, expected (N, 3)")
    return PointTable(points, fields, about)


def read_points_info(path: str | os.PathLike[str]) -> PointFileInfo:
    """Read a point file; return its finite points (and their fields) and how many rows
    were dropped."""
    table = read_point_table(path)
    points = table.points
    if len(points) == 0:
        raise PointFileError(f"{path}: no points (empty or unreadable file)")
    finite = np.isfinite(points).all(axis=1)
    if not finite.any():
        raise PointFileError(f"{path}: no finite points ({len(points)} rows)")
    kept = np.ascontiguousarray(points[finite], dtype=np.float64)
    fields = {k: v[finite] for k, v in table.fields.items()}
    return PointFileInfo(kept, len(points), int(len(points) - len(kept)), fields)


def describe_points(path: str | os.PathLike[str]) -> PointSummary:
    """What a point file holds (``alte info FILE``): format, encoding, fields, rows,
    finite points, non-finite rows, the finite points' bounds, and per field its range."""
    table = read_point_table(path)
    finite = np.isfinite(table.points).all(axis=1)
    kept = table.points[finite]
    bounds = [kept.min(axis=0).tolist(), kept.max(axis=0).tolist()] if len(kept) else None
    ranges = {k: [float(np.min(v)), float(np.max(v))] for k, v in table.fields.items()
              if v.size and v.dtype.kind in "biuf"}
    return {"file": str(path), **table.about, "rows": len(table.points),
            "points": int(finite.sum()), "nonfinite": int((~finite).sum()),
            "nan": int(np.isnan(table.points).any(axis=1).sum()), "bounds": bounds,
            "field_ranges": ranges}


def read_points(path: str | os.PathLike[str]) -> NDArray[np.float64]:
    """(N, 3) float64 points of a PCD, PLY, LAS/LAZ, npz or xyz file; non-finite rows dropped."""
    return read_points_info(path).points


# ------------------------------------------------------------------------------ writers

_WRITERS: dict[str, Callable[[Path, NDArray[np.float64], Fields], None]] = {
    ".pcd": write_pcd, ".ply": write_ply, ".npz": write_npz}
_WRITERS |= {s: write_text for s in _TEXT}
_WRITERS |= {
    ".las": lambda t, p, f: write_las(t, p, f, False),
    ".laz": lambda t, p, f: write_las(t, p, f, True),
}


def write_points(path: str | os.PathLike[str], points: NDArray[np.float64], overwrite: bool = False,
                 fields: Fields | None = None) -> Path:
    """Write (N, 3) points atomically as PCD (binary, float64), PLY, npz, xyz text or LAS/LAZ,
    with the ``fields`` (N rows each) the format can hold (:func:`storable`)."""
    path = Path(path)
    writer = _WRITERS.get(_suffix(path))
    if writer is None:
        raise PointFileError(f"{path}: cannot write this type; supported: {WRITE_SUFFIXES}")
    arr = np.asarray(points, dtype=np.float64)
    if arr.ndim != 2 or arr.shape[1] != 3 or len(arr) == 0:
        raise PointFileError(f"{path}: points must have shape (N, 3) with N > 0, got {arr.shape}")
    if not np.isfinite(arr).all():
        raise PointFileError(f"{path}: refusing to write non-finite coordinates")
    given = {k: np.asarray(v) for k, v in (fields or {}).items()}
    wrong = sorted(k for k, v in given.items() if v.ndim == 0 or len(v) != len(arr))
    if wrong:
        raise PointFileError(f"{path}: fields {wrong} do not have one row per point "
                             f"({len(arr)})")
    if path.exists() and not overwrite:
        raise PointFileError(f"{path} already exists; pass overwrite=True to replace it")
    kept, _ = storable(_suffix(path), given)
    with atomic_path(path, overwrite=overwrite) as tmp:
        writer(tmp, np.ascontiguousarray(arr), kept)
    return path
