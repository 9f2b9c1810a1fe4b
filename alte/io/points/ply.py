"""PLY point clouds: a numpy reader keeping every vertex property, and a binary writer.

A point-cloud PLY (one ``vertex`` element of scalar properties, ascii or binary) is read
with numpy so that every property is kept (open3d's readers skip 16-bit ones); red,
green and blue become ``colors`` (N, 3). Other PLYs (meshes, list properties) go
through open3d's tensor reader. A body shorter than the header announces is refused.
"""

from __future__ import annotations

from pathlib import Path
from typing import NotRequired, TypedDict

import numpy as np
from numpy.typing import NDArray

from alte.errors import PointFileError
from alte.io.points.pcd import Fields, read_table

__all__ = ["FieldInfo", "Fields", "FileAbout", "ply_layout", "read_ply", "write_ply"]


class FieldInfo(TypedDict):
    """One field a point file declares: its name, type (as the file spells it) and values
    per point."""

    name: str
    type: str
    count: int


class FileAbout(TypedDict):
    """What a point file says of itself (a JSON object of ``alte info --json``): format,
    encoding and declared fields; a PCD also its layout and viewpoint."""

    format: str
    encoding: str
    fields: list[FieldInfo]
    width: NotRequired[int]
    height: NotRequired[int]
    viewpoint: NotRequired[list[float]]

_PLY_SIZES = {"char": 1, "int8": 1, "uchar": 1, "uint8": 1, "short": 2, "int16": 2,
              "ushort": 2, "uint16": 2, "int": 4, "int32": 4, "uint": 4, "uint32": 4,
              "float": 4, "float32": 4, "double": 8, "float64": 8}


_PLY_NUMPY = {"char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1", "short": "i2",
              "int16": "i2", "ushort": "u2", "uint16": "u2", "int": "i4", "int32": "i4",
              "uint": "u4", "uint32": "u4", "float": "f4", "float32": "f4", "double": "f8",
              "float64": "f8"}


def ply_layout(path: Path) -> tuple[str, int, int, list[list[str]]]:
    """(format, header bytes, minimum body: bytes if binary, rows if ascii, and the element
    and property lines, split into words)."""
    with open(path, "rb") as fh:
        head = fh.read(65536)
    end = head.find(b"end_header")
    if not head.startswith(b"ply") or end < 0:
        raise PointFileError(f"{path}: not a PLY file (no 'ply' ... 'end_header' header)")
    fmt, rows, size, count, lines = "", 0, 0, 0, []
    for line in head[:end].decode("ascii", "replace").splitlines():
        word = line.split()
        if word[:1] == ["format"] and len(word) > 1:
            fmt = word[1]
        elif word[:1] == ["element"] and len(word) > 2:
            count = int(word[2])
            rows += count
            lines.append(word)
        elif word[:1] == ["property"] and len(word) > 2:  # a list counts its length field
            size += count * _PLY_SIZES.get(word[2] if word[1] == "list" else word[1], 0)
            lines.append(word)
    body_start = head.index(b"\n", end) + 1
    return fmt, body_start, rows if fmt == "ascii" else size, lines


def _check_ply_complete(path: Path) -> tuple[str, int, list[list[str]]]:
    """Raise when the body is shorter than the header announces (open3d only warns)."""
    fmt, start, need, lines = ply_layout(path)
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
    return fmt, start, lines


def _vertex_dtype(fmt: str, lines: list[list[str]]) -> np.dtype[np.void] | None:
    """The body's row type when it is one ``vertex`` element of scalar properties (a
    point cloud), else None (meshes, lists: left to open3d)."""
    elements = [w for w in lines if w[0] == "element"]
    props = [w for w in lines if w[0] == "property"]
    order = {"binary_little_endian": "<", "binary_big_endian": ">", "ascii": "<"}
    if len(elements) != 1 or elements[0][1] != "vertex" or fmt not in order or any(
            w[1] not in _PLY_NUMPY for w in props):
        return None
    return np.dtype([(w[2], order[fmt] + _PLY_NUMPY[w[1]]) for w in props])


def read_ply(path: Path) -> tuple[NDArray[np.float64], Fields, FileAbout]:
    """A point-cloud PLY (one vertex element) read with numpy, every property kept (red,
    green, blue as ``colors``); other PLYs through open3d's tensor reader."""
    fmt, start, lines = _check_ply_complete(path)
    about: FileAbout = {"format": "PLY", "encoding": fmt, "fields": [
        {"name": w[-1], "type": " ".join(w[1:-1]), "count": 1}
        for w in lines if w[0] == "property"]}
    dtype = _vertex_dtype(fmt, lines)
    if dtype is None:
        return (*_read_ply_open3d(path), about)
    count = int(next(w for w in lines if w[0] == "element")[2])
    if fmt == "ascii":
        table = read_table(path, offset=start).to_numpy()[:count]
        rows = np.empty(count, dtype)
        for k, name in enumerate(dtype.names or ()):
            rows[name] = table[:, k]
    else:
        rows = np.frombuffer(path.read_bytes(), dtype, count=count, offset=start)
    names = list(dtype.names or ())
    if not {"x", "y", "z"} <= set(names):
        raise PointFileError(f"{path}: PLY vertex properties {names} lack x, y and z")
    points = np.column_stack([rows[c] for c in "xyz"]).astype(np.float64)
    fields = {n: rows[n].astype(rows[n].dtype.newbyteorder("=")) for n in names
              if n not in ("x", "y", "z", "red", "green", "blue")}
    if {"red", "green", "blue"} <= set(names):
        fields["colors"] = np.column_stack([rows[c] for c in ("red", "green", "blue")])
    return points, fields, about


def _read_ply_open3d(path: Path) -> tuple[NDArray[np.float64], Fields]:
    import open3d as o3d

    with o3d.utility.VerbosityContextManager(o3d.utility.VerbosityLevel.Error):
        cloud = o3d.t.io.read_point_cloud(path, format="ply")
    attrs = {k: cloud.point[k].numpy() for k in cloud.point}
    points = attrs.pop("positions", np.empty((0, 3))).astype(np.float64)
    fields = {k: (v[:, 0] if v.ndim == 2 and v.shape[1] == 1 else v).copy()
              for k, v in sorted(attrs.items())}
    return points, fields


def write_ply(tmp: Path, points: NDArray[np.float64], fields: Fields) -> None:
    """Binary little-endian PLY: double x y z, then each field as properties (colors as
    uchar red green blue)."""
    columns: list[tuple[str, NDArray[np.generic[object]]]] = [
        ("x", points[:, 0]), ("y", points[:, 1]), ("z", points[:, 2])]
    for name, values in fields.items():
        if name == "colors":
            columns += [(c, values[:, k]) for k, c in enumerate(("red", "green", "blue"))]
        elif values.ndim == 1:
            columns.append((name, values))
        else:
            columns += [(f"{name}_{k}", values[:, k]) for k in range(values.shape[1])]
    kinds = {"f8": "double", "f4": "float", "i1": "char", "u1": "uchar", "i2": "short",
             "u2": "ushort", "i4": "int", "u4": "uint", "b1": "uchar"}
    dtype = np.dtype([(n, "<" + _ply_code(v)) for n, v in columns])
    body = np.empty(len(points), dtype)
    for name, values in columns:
        body[name] = values
    header = ["ply", "format binary_little_endian 1.0", "comment written by alte",
              f"element vertex {len(points)}"]
    header += [f"property {kinds[_ply_code(v)]} {n}" for n, v in columns]
    tmp.write_bytes(("\n".join([*header, "end_header"]) + "\n").encode("ascii")
                    + body.tobytes())


def _ply_code(values: NDArray[np.generic[object]]) -> str:
    """PLY-representable dtype code (64-bit integers go as float64, bools as uchar)."""
    kind, size = values.dtype.kind, values.dtype.itemsize
    if kind == "b":
        return "u1"
    if kind in "iu" and size <= 4:
        return f"{kind}{size}"
    return "f4" if kind == "f" and size == 4 else "f8"
