"""Terrains as triangle meshes with an object id per triangle (the ground truth).

A :class:`SceneBuilder` assembles convex building blocks (boxes, cylinders, gable
prisms, spheres, ground rectangles); every block is one object with a class from
:data:`CLASSES`. The finished :class:`Scene` is plain arrays, ray-cast by open3d's
``RaycastingScene`` (see :mod:`alte.sim.sensor`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from alte.tensors import to_tensor

if TYPE_CHECKING:
    import open3d as o3d

__all__ = ["CLASSES", "Scene", "SceneBuilder", "SceneObject"]

#: Object classes of the ground truth, index = ``class_id`` stored per triangle.
CLASSES: tuple[str, ...] = (
    "ground", "wall", "building", "overhang", "beam", "pillar", "car", "tree", "fence",
    "debris", "buoy", "room", "vegetation", "object",
)


@dataclass(frozen=True)
class SceneObject:
    """One object of a scene: its name and class (one of :data:`CLASSES`)."""

    name: str
    cls: str

    @property
    def class_id(self) -> int:
        """Index of the class in :data:`CLASSES`."""
        return CLASSES.index(self.cls)


@dataclass(frozen=True, eq=False)
class Scene:
    """A triangle mesh with the object each triangle belongs to."""

    vertices: NDArray[np.float64]
    triangles: NDArray[np.int32]
    object_ids: NDArray[np.int32]
    objects: tuple[SceneObject, ...]

    @property
    def class_ids(self) -> NDArray[np.uint8]:
        """Class index per triangle."""
        lut = np.array([o.class_id for o in self.objects], dtype=np.uint8)
        ids: NDArray[np.uint8] = lut[self.object_ids]
        return ids

    @property
    def labels(self) -> dict[int, str]:
        """Object id -> object name."""
        return {i: o.name for i, o in enumerate(self.objects)}

    @property
    def classes(self) -> dict[int, str]:
        """Object id -> object class."""
        return {i: o.cls for i, o in enumerate(self.objects)}

    def raycaster(self) -> o3d.t.geometry.RaycastingScene:
        """An ``open3d.t.geometry.RaycastingScene`` holding the mesh (geometry id 0)."""
        import open3d as o3d

        rc = o3d.t.geometry.RaycastingScene()
        rc.add_triangles(to_tensor(self.vertices), to_tensor(self.triangles, np.uint32))
        return rc

    def bounds(self) -> NDArray[np.float64]:
        """``(xmin, ymin, zmin, xmax, ymax, zmax)`` of the mesh."""
        return np.concatenate([self.vertices.min(axis=0), self.vertices.max(axis=0)])


def _orient_outward(vertices: NDArray[np.float64], triangles: NDArray[np.int64]
                    ) -> NDArray[np.int64]:
    """Flip triangles of a convex part so their normals point away from its centre."""
    tri = vertices[triangles]
    normals = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    outward = np.einsum("ij,ij->i", normals, tri.mean(axis=1) - vertices.mean(axis=0)) < 0
    fixed = triangles.copy()
    fixed[outward] = fixed[outward][:, [0, 2, 1]]
    return fixed


def _ring(radius: float, segments: int) -> NDArray[np.float64]:
    ang = np.arange(segments) * (2 * np.pi / segments)
    return np.column_stack([radius * np.cos(ang), radius * np.sin(ang)])


_BOX_TRIS = np.array([
    [0, 1, 3], [0, 3, 2], [4, 5, 7], [4, 7, 6], [0, 1, 5], [0, 5, 4],
    [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 3, 7], [1, 7, 5],
])


@dataclass
class SceneBuilder:
    """Collects convex parts; :meth:`build` returns the :class:`Scene`."""

    _verts: list[NDArray[np.float64]] = field(default_factory=list)
    _tris: list[NDArray[np.int64]] = field(default_factory=list)
    _ids: list[NDArray[np.int32]] = field(default_factory=list)
    _objects: list[SceneObject] = field(default_factory=list)
    _count: int = 0

    def add(self, name: str, cls: str, vertices: NDArray[np.float64], triangles: NDArray[np.int64],
            convex: bool = True) -> int:
        """Add a part as its own object; returns the object id."""
        if cls not in CLASSES:
            raise ValueError(f"object {name!r}: unknown class {cls!r}; valid: {', '.join(CLASSES)}")
        tris = _orient_outward(vertices, triangles) if convex else triangles
        obj_id = len(self._objects)
        self._objects.append(SceneObject(name, cls))
        self._verts.append(np.asarray(vertices, dtype=np.float64))
        self._tris.append(tris.astype(np.int64) + self._count)
        self._ids.append(np.full(len(tris), obj_id, dtype=np.int32))
        self._count += len(vertices)
        return obj_id

    def box(self, name: str, cls: str, center: tuple[float, float, float],
            size: tuple[float, float, float], yaw_deg: float = 0.0) -> int:
        """An axis-aligned (then yawed about z) box; ``center`` z is the box's mid-height."""
        bits = np.array([[i & 1, (i >> 1) & 1, (i >> 2) & 1] for i in range(8)], dtype=float)
        local = (bits - 0.5) * np.asarray(size, dtype=float)
        return self.add(name, cls, _yawed(local, yaw_deg) + np.asarray(center), _BOX_TRIS)

    def slab(self, name: str, cls: str, xy: tuple[float, float], size_xy: tuple[float, float],
             *, z: tuple[float, float], yaw_deg: float = 0.0) -> int:
        """A box given by its footprint centre, footprint size and bottom/top heights ``z``."""
        z0, z1 = z
        return self.box(name, cls, (xy[0], xy[1], 0.5 * (z0 + z1)),
                        (size_xy[0], size_xy[1], z1 - z0), yaw_deg)

    def cylinder(self, name: str, cls: str, xy: tuple[float, float], radius: float,
                 *, z: tuple[float, float], segments: int = 24) -> int:
        """A vertical capped cylinder from ``z[0]`` to ``z[1]``."""
        z0, z1 = z
        ring = _ring(radius, segments) + np.asarray(xy, dtype=float)
        verts = np.vstack([np.column_stack([ring, np.full(segments, z0)]),
                           np.column_stack([ring, np.full(segments, z1)]),
                           [[xy[0], xy[1], z0], [xy[0], xy[1], z1]]])
        i = np.arange(segments)
        j = (i + 1) % segments
        n = segments
        tris = np.vstack([np.column_stack([i, j, j + n]), np.column_stack([i, j + n, i + n]),
                          np.column_stack([i, j, np.full(n, 2 * n)]),
                          np.column_stack([i + n, j + n, np.full(n, 2 * n + 1)])])
        return self.add(name, cls, verts, tris)

    def gable(self, name: str, cls: str, xy: tuple[float, float], *, size: tuple[float, float],
              z: tuple[float, float], yaw_deg: float = 0.0) -> int:
        """A gable roof: prism along local x, ``size`` = (length, width), ``z`` = (eaves, ridge)."""
        hl, hw = 0.5 * size[0], 0.5 * size[1]
        z0, ridge = z
        local = np.array([[-hl, -hw, z0], [-hl, hw, z0], [-hl, 0, ridge],
                          [hl, -hw, z0], [hl, hw, z0], [hl, 0, ridge]])
        tris = np.array([[0, 1, 2], [3, 4, 5], [0, 3, 4], [0, 4, 1], [0, 2, 5], [0, 5, 3],
                         [1, 4, 5], [1, 5, 2]])
        verts = _yawed(local, yaw_deg) + np.array([xy[0], xy[1], 0.0])
        return self.add(name, cls, verts, tris)

    def sphere(self, name: str, cls: str, center: tuple[float, float, float], radius: float,
               resolution: int = 12) -> int:
        """A sphere (open3d's UV sphere)."""
        import open3d as o3d

        mesh = o3d.geometry.TriangleMesh.create_sphere(radius=radius, resolution=resolution)
        verts = np.asarray(mesh.vertices) + np.asarray(center, dtype=float)
        return self.add(name, cls, verts, np.asarray(mesh.triangles))

    def ground(self, name: str, extent: tuple[float, float, float, float], z: float = 0.0,
               cls: str = "ground") -> int:
        """A horizontal rectangle ``(xmin, ymin, xmax, ymax)`` facing up."""
        x0, y0, x1, y1 = extent
        verts = np.array([[x0, y0, z], [x1, y0, z], [x1, y1, z], [x0, y1, z]], dtype=float)
        return self.add(name, cls, verts, np.array([[0, 1, 2], [0, 2, 3]]), convex=False)

    def build(self) -> Scene:
        """The assembled scene."""
        if not self._objects:
            raise ValueError("a scene needs at least one object")
        return Scene(np.vstack(self._verts), np.vstack(self._tris).astype(np.int32),
                     np.concatenate(self._ids), tuple(self._objects))


def _yawed(local: NDArray[np.float64], yaw_deg: float) -> NDArray[np.float64]:
    c, s = np.cos(np.radians(yaw_deg)), np.sin(np.radians(yaw_deg))
    rot = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    yawed: NDArray[np.float64] = local @ rot.T
    return yawed
