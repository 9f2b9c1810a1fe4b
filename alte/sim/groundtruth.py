"""Ground-truth meshes: binary PLY with an object id and class id per triangle.

The PLY is standard (MeshLab, VTK and open3d read its geometry); the extra face
properties ``object_id`` (int) and ``class_id`` (uchar) carry the labels, and
``comment object <id> <class> <name>`` header lines name the objects. Written with
numpy structured arrays, so the same scene gives the same bytes.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from alte.errors import PointFileError
from alte.fsutil import atomic_path
from alte.sim.scene import CLASSES, Scene, SceneObject
from alte.tensors import to_array, to_tensor

__all__ = ["GROUND_TRUTH_FILE", "load_ground_truth", "mesh_distance", "read_ground_truth",
           "write_ground_truth"]

GROUND_TRUTH_FILE = "ground_truth.ply"

_VERTEX = np.dtype([("x", "<f8"), ("y", "<f8"), ("z", "<f8")])
_FACE = np.dtype([("n", "u1"), ("v", "<i4", (3,)), ("object_id", "<i4"), ("class_id", "u1")])


def write_ground_truth(path: str | os.PathLike[str], scene: Scene,
                       overwrite: bool = False) -> Path:
    """Write ``scene`` as a binary little-endian PLY with per-face labels."""
    header = ["ply", "format binary_little_endian 1.0", "comment alte ground truth"]
    header += [f"comment object {i} {o.cls} {o.name}" for i, o in enumerate(scene.objects)]
    header += [f"element vertex {len(scene.vertices)}", "property double x",
               "property double y", "property double z", f"element face {len(scene.triangles)}",
               "property list uchar int vertex_indices", "property int object_id",
               "property uchar class_id", "end_header"]
    verts = np.empty(len(scene.vertices), dtype=_VERTEX)
    for i, axis in enumerate("xyz"):
        verts[axis] = scene.vertices[:, i]
    faces = np.empty(len(scene.triangles), dtype=_FACE)
    faces["n"], faces["v"] = 3, scene.triangles
    faces["object_id"], faces["class_id"] = scene.object_ids, scene.class_ids
    with atomic_path(path, overwrite=overwrite) as tmp, open(tmp, "wb") as fh:
        fh.write(("\n".join(header) + "\n").encode("ascii"))
        fh.write(verts.tobytes())
        fh.write(faces.tobytes())
    return Path(path)


def _parse_header(path: Path, raw: bytes) -> tuple[int, int, int, list[SceneObject]]:
    end = raw.find(b"end_header\n")
    if not raw.startswith(b"ply\n") or end < 0:
        raise PointFileError(f"{path}: not a PLY file (missing 'ply' / 'end_header')")
    lines = raw[:end].decode("ascii", errors="replace").splitlines()
    if "format binary_little_endian 1.0" not in lines or "comment alte ground truth" not in lines:
        raise PointFileError(f"{path}: not an alte ground-truth PLY (binary, per-face ids)")
    counts = {ln.split()[1]: int(ln.split()[2]) for ln in lines if ln.startswith("element ")}
    objects = []
    for ln in lines:
        if ln.startswith("comment object "):
            _, _, _, cls, name = ln.split(maxsplit=4)
            objects.append(SceneObject(name, cls))
    if set(counts) != {"vertex", "face"}:
        raise PointFileError(f"{path}: expected vertex and face elements, got {sorted(counts)}")
    return end + len(b"end_header\n"), counts["vertex"], counts["face"], objects


def read_ground_truth(path: str | os.PathLike[str]) -> Scene:
    """Read a PLY written by :func:`write_ground_truth` back into a :class:`Scene`."""
    path = Path(path)
    try:
        raw = path.read_bytes()
    except OSError as err:
        raise PointFileError(f"cannot read ground truth {path}: {err}") from err
    start, n_vert, n_face, objects = _parse_header(path, raw)
    need = start + n_vert * _VERTEX.itemsize + n_face * _FACE.itemsize
    if len(raw) != need:
        raise PointFileError(f"{path}: {len(raw)} bytes, header promises {need} (truncated?)")
    verts = np.frombuffer(raw, dtype=_VERTEX, count=n_vert, offset=start)
    faces = np.frombuffer(raw, dtype=_FACE, count=n_face, offset=start + verts.nbytes)
    ids = faces["object_id"].astype(np.int32)
    if n_face and (ids.min() < 0 or ids.max() >= len(objects)):
        raise PointFileError(f"{path}: object ids outside the {len(objects)} named objects")
    if any(o.cls not in CLASSES for o in objects):
        raise PointFileError(f"{path}: unknown object class in header")
    vertices = np.column_stack([verts["x"], verts["y"], verts["z"]])
    triangles: NDArray[np.int32] = faces["v"].astype(np.int32)
    return Scene(vertices, triangles, ids, tuple(objects))


def load_ground_truth(directory: str | os.PathLike[str]) -> Scene:
    """The ground-truth scene of a simulated terrain folder (``DIR/NAME``)."""
    return read_ground_truth(Path(directory) / GROUND_TRUTH_FILE)


def mesh_distance(points: NDArray[np.float64], scene: Scene) -> NDArray[np.float64]:
    """Unsigned distance (N,) from each point to the nearest triangle of ``scene``."""
    pts = np.asarray(points).reshape(-1, 3)
    return to_array(scene.raycaster().compute_distance(to_tensor(pts)), np.float64)
