"""Readers and writers of the point formats other than PCD, with their non-coordinate fields.

Each reader returns ``(points, fields, about)``: (N, 3) float64 coordinates with every row
(non-finite ones included), the other per-point fields by name ((N,) or (N, k) arrays;
colours as ``colors`` (N, 3) uint8 whatever the format calls them) and what the file says
of itself (format, encoding, its fields with their types). A point-cloud PLY (one vertex
element of scalar properties) is read with numpy, every property kept (open3d's readers
skip 16-bit ones); other PLYs (meshes) go through open3d's tensor reader; LAS/LAZ
through laspy (scaled coordinates; the standard dimensions that carry data, and
extra-bytes dimensions); ``.npz`` keeps every array of N rows beside ``points``; plain
text is x y z (extra columns are ignored).

Writers take the fields a format can hold (:func:`storable`): PLY, ``.npz`` and PCD any
numeric field; LAS/LAZ integer ``intensity`` (0..65535) and ``classification`` (0..255),
``colors`` and any other numeric field as an extra-bytes dimension; text none.
"""

from __future__ import annotations

import datetime
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from alte.errors import ParameterError, PointFileError
from alte.io.points.pcd import read_table
from alte.io.points.ply import FieldInfo, Fields, FileAbout, read_ply, write_ply

__all__ = ["FieldInfo", "Fields", "FileAbout", "local_origin", "read_las", "read_npz",
           "read_ply", "read_text", "storable", "write_las", "write_npz", "write_ply",
           "write_text"]

_LAS_SCALE = 1e-4
#: The header's creation day: fixed, as numpy fixes the dates inside ``.npz`` files, so the
#: same cloud gives the same bytes on any day.
_LAS_DATE = datetime.date(1980, 1, 1)
_LAS_STANDARD = ("intensity", "classification", "gps_time")
#: Dimension names of LAS point formats 6-8 (a field of one of these names is not extra).
_LAS_RESERVED = frozenset({"x", "y", "z", "intensity", "return_number", "number_of_returns",
                           "synthetic", "key_point", "withheld", "overlap", "scanner_channel",
                           "scan_direction_flag", "edge_of_flight_line", "classification",
                           "user_data", "scan_angle", "point_source_id", "gps_time", "red",
                           "green", "blue", "nir"})

def _describe(fields: Fields) -> list[FieldInfo]:
    return [{"name": k, "type": str(v.dtype), "count": int(np.prod(v.shape[1:], dtype=int))}
            for k, v in fields.items()]


# ------------------------------------------------------------------------------ LAS


def read_las(path: Path) -> tuple[NDArray[np.float64], Fields, FileAbout]:
    import laspy

    las = laspy.read(path)
    points = np.column_stack([np.asarray(las.x), np.asarray(las.y), np.asarray(las.z)])
    dims = set(las.point_format.dimension_names)
    fields: Fields = {k: np.asarray(las[k]) for k in _LAS_STANDARD
                      if k in dims and np.any(np.asarray(las[k]))}
    if {"red", "green", "blue"} <= dims:
        rgb = np.column_stack([np.asarray(las[c]) for c in ("red", "green", "blue")])
        if rgb.any():
            fields["colors"] = (rgb >> 8 if rgb.max() > 255 else rgb).astype(np.uint8)
    for name in las.point_format.extra_dimension_names:
        fields[name] = np.asarray(las[name])
    head = las.header
    about: FileAbout = {
        "format": f"LAS {head.version} point format {head.point_format.id}",
        "encoding": "laz" if path.suffix.lower() == ".laz" else "las",
        "fields": [{"name": d.name, "type": str(d.dtype) if d.dtype is not None
                    else f"{d.num_bits} bit", "count": 1}
                   for d in las.point_format.dimensions]}
    return points, fields, about


def _fits(values: NDArray[np.generic[object]], top: int) -> bool:
    return bool(values.ndim == 1 and np.all(np.isfinite(values))
                and np.all(np.greater_equal(values, 0)) and np.all(np.less_equal(values, top))
                and np.all(np.equal(np.mod(values, 1), 0)))


def write_las(tmp: Path, points: NDArray[np.float64], fields: Fields, compress: bool) -> None:
    import laspy

    fields = dict(fields)
    colors = fields.pop("colors", None)
    fmt = (7 if colors is not None else 6) if fields or colors is not None else 0
    header = laspy.LasHeader(point_format=fmt, version="1.4" if fmt else "1.2")
    header.creation_date = _LAS_DATE
    header.offsets = local_origin(points)
    header.scales = np.full(3, _LAS_SCALE)
    reach = np.abs(points - header.offsets).max() / _LAS_SCALE
    if reach >= 2**31 - 1:
        raise PointFileError(f"{tmp}: cloud spans too far for LAS at {_LAS_SCALE} m resolution")
    extra = {k: v for k, v in fields.items() if k not in _LAS_STANDARD}
    header.add_extra_dims([laspy.ExtraBytesParams(name=k, type=v.dtype) for k, v in
                           extra.items()])
    las = laspy.LasData(header)
    las.x, las.y, las.z = points[:, 0], points[:, 1], points[:, 2]
    for name, values in fields.items():
        las[name] = values.astype(np.asarray(las[name]).dtype) if name in _LAS_STANDARD \
            else values
    if colors is not None:
        for k, c in enumerate(("red", "green", "blue")):
            las[c] = colors[:, k].astype(np.uint16) * 257
    with open(tmp, "wb") as fh:
        las.write(fh, do_compress=compress)


# ------------------------------------------------------------------------------ npz, text


def read_npz(path: Path) -> tuple[NDArray[np.float64], Fields, FileAbout]:
    with np.load(path, allow_pickle=False) as archive:
        if "points" not in archive.files:
            raise PointFileError(f"{path}: no 'points' array (has {archive.files})")
        points = np.asarray(archive["points"], dtype=np.float64)
        fields = {k: archive[k] for k in archive.files if k != "points"
                  and archive[k].ndim >= 1 and len(archive[k]) == len(points)}
    about: FileAbout = {"format": "npz", "encoding": "zip", "fields": [
        {"name": "points", "type": "float64", "count": 3}, *_describe(fields)]}
    return points, fields, about


def write_npz(tmp: Path, points: NDArray[np.float64], fields: Fields) -> None:
    with open(tmp, "wb") as fh:  # a handle stops numpy appending ".npz"
        arrays: Fields = {"points": points, **fields}
        np.savez_compressed(fh, allow_pickle=True, **arrays)


def read_text(path: Path) -> tuple[NDArray[np.float64], Fields, FileAbout]:
    table = read_table(path)
    if table.shape[1] < 3:
        raise PointFileError(f"{path}: {table.shape[1]} column(s); expected x y z per line")
    described: list[FieldInfo] = [{"name": c, "type": "text", "count": 1} for c in "xyz"]
    described += [{"name": f"column {k + 1} (ignored)", "type": "text", "count": 1}
                  for k in range(3, table.shape[1])]
    about: FileAbout = {"format": "text",
                        "encoding": "bzip2" if path.suffix.lower() == ".bz2" else "ascii",
                        "fields": described}
    return table.iloc[:, :3].to_numpy(np.float64), {}, about


def write_text(tmp: Path, points: NDArray[np.float64], fields: Fields) -> None:
    del fields  # plain text holds x y z only (:func:`storable`)
    # pandas prints the shortest repr that round-trips each float64 exactly
    import pandas as pd  # on first use: pandas is ~80 MB resident

    pd.DataFrame(points).to_csv(tmp, sep=" ", header=False, index=False)


def _las_refusal(name: str, values: NDArray[np.generic[object]]) -> str | None:
    """Why a LAS 1.4 file (point format 6/7) cannot hold a field, or None."""
    limits = {"intensity": 65535, "classification": 255}
    if name in limits and not _fits(values, limits[name]):
        return f"LAS {name} holds integers 0..{limits[name]}"
    if name == "colors":
        return None if values.dtype == np.uint8 else "LAS colours here are 8-bit"
    if name in _LAS_RESERVED and name not in _LAS_STANDARD:
        return "a LAS standard dimension of that name means something else"
    if values.ndim != 1 and name not in _LAS_STANDARD:
        return "LAS extra bytes hold one value per point here"
    return None


def storable(suffix: str, fields: Fields) -> tuple[Fields, dict[str, str]]:
    """The fields a file of ``suffix`` holds, and why each other one is left out."""
    kept, dropped = {}, {}
    for name, values in fields.items():
        reason = None
        if values.dtype.kind not in "biuf":
            reason = f"{values.dtype} values"
        elif suffix in (".las", ".laz"):
            reason = _las_refusal(name, values)
        elif suffix not in (".pcd", ".ply", ".npz"):
            reason = "plain text holds x y z only"
        if reason is None:
            kept[name] = values
        else:
            dropped[name] = reason
    return kept, dropped


def local_origin(points: NDArray[np.float64], quantum: float = 1000.0) -> NDArray[np.float64]:
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
    origin: NDArray[np.float64] = np.round(centre / quantum) * quantum + 0.0  # + 0.0: -0.0 -> 0.0
    return origin
