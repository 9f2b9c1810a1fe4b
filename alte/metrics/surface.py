"""The simulator's true surface as a queryable object: samples, distances, inside tests.

Wraps the ground-truth triangle mesh (vertices, triangles, one object id per triangle)
in an open3d ``RaycastingScene`` so that point-to-mesh distances, vertical height
probes and inside/outside tests are vectorized C++ calls. Samples are drawn with a
seeded numpy generator (uniform by area) so every metric is reproducible.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from alte.errors import MetricsError
from alte.tensors import to_array, to_tensor

if TYPE_CHECKING:  # open3d (~200 MB resident) is imported on first use, as everywhere else
    import open3d as o3d

__all__ = ["SurfaceSamples", "TrueSurface"]

#: Direction of the inside-test rays: near-vertical, tilted so that rays from grid-aligned
#: cell centres do not graze the edges of axis-aligned boxes.
_UP = np.array([1.3e-3, 2.1e-3, 1.0]) / np.linalg.norm([1.3e-3, 2.1e-3, 1.0])


@dataclass(frozen=True)
class SurfaceSamples:
    """Points drawn on the true surface and the object id of the triangle each lies on."""

    points: NDArray[np.float64]
    object_ids: NDArray[np.int64]

    def __len__(self) -> int:
        return int(self.points.shape[0])

    def subset(self, mask: NDArray[np.bool_]) -> SurfaceSamples:
        """The samples where ``mask`` is true."""
        return SurfaceSamples(self.points[mask], self.object_ids[mask])


class TrueSurface:
    """Ground-truth mesh: ``vertices`` (V, 3), ``triangles`` (T, 3), ``object_ids`` (T,).

    ``labels`` names objects by id (e.g. ``"roof_1"``), ``classes`` gives their class
    (e.g. ``"overhang"``); both are optional and only used to key per-object metrics.
    """

    def __init__(self, vertices: object, triangles: object, object_ids: object | None = None,
                 labels: dict[int, str] | None = None,
                 classes: dict[int, str] | None = None) -> None:
        self.vertices = np.asarray(vertices, dtype=np.float64)
        self.triangles = np.asarray(triangles, dtype=np.int64)
        if self.vertices.ndim != 2 or self.vertices.shape[1] != 3 or len(self.vertices) == 0:
            raise MetricsError(f"true surface: vertices must be (V, 3), got {self.vertices.shape}")
        if self.triangles.ndim != 2 or self.triangles.shape[1] != 3 or len(self.triangles) == 0:
            raise MetricsError(
                f"true surface: triangles must be (T, 3), got {self.triangles.shape}")
        if self.triangles.min() < 0 or self.triangles.max() >= len(self.vertices):
            raise MetricsError("true surface: triangle indices out of range of the vertices")
        ids = np.zeros(len(self.triangles), np.int64) if object_ids is None else object_ids
        self.object_ids = np.asarray(ids, dtype=np.int64).reshape(-1)
        if self.object_ids.shape[0] != self.triangles.shape[0]:
            raise MetricsError(f"true surface: {self.object_ids.shape[0]} object ids for "
                               f"{self.triangles.shape[0]} triangles")
        self.labels = dict(labels or {})
        self.classes = dict(classes or {})
        import open3d as o3d

        self._scene = o3d.t.geometry.RaycastingScene()
        mesh = o3d.t.geometry.TriangleMesh()
        mesh.vertex.positions = to_tensor(self.vertices)
        mesh.triangle.indices = to_tensor(self.triangles, np.uint32)
        self._scene.add_triangles(mesh)
        self._objects: list[tuple[NDArray[np.float64], NDArray[np.float64],
                                  o3d.t.geometry.RaycastingScene]] | None = None

    def triangle_areas(self) -> NDArray[np.float64]:
        """Area of every triangle (m^2)."""
        v = self.vertices[self.triangles]
        areas: NDArray[np.float64] = 0.5 * np.linalg.norm(
            np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0]), axis=1)
        return areas

    def sample(self, count: int, seed: int = 0,
               bounds: NDArray[np.float64] | None = None) -> SurfaceSamples:
        """``count`` points drawn uniformly by area with a seeded generator.

        ``bounds`` (2, 3) = min/max corner: samples outside are dropped afterwards, so
        fewer than ``count`` points may come back.
        """
        if count < 1:
            raise MetricsError(f"true surface: sample count must be >= 1, got {count}")
        areas = self.triangle_areas()
        if areas.sum() <= 0:
            raise MetricsError("true surface: no triangle with positive area to sample")
        rng = np.random.default_rng(seed)
        tri = rng.choice(len(areas), size=count, p=areas / areas.sum())
        r1, r2 = np.sqrt(rng.random(count)), rng.random(count)
        v = self.vertices[self.triangles[tri]]
        pts = ((1 - r1)[:, None] * v[:, 0] + (r1 * (1 - r2))[:, None] * v[:, 1]
               + (r1 * r2)[:, None] * v[:, 2])
        samples = SurfaceSamples(pts, self.object_ids[tri])
        if bounds is None:
            return samples
        lo, hi = np.asarray(bounds, dtype=np.float64)
        return samples.subset(np.all((pts >= lo) & (pts <= hi), axis=1))

    def distance(self, points: NDArray[np.float64]) -> NDArray[np.float64]:
        """Unsigned distance from each point (N, 3) to the nearest triangle."""
        if len(points) == 0:
            return np.zeros(0)
        return to_array(self._scene.compute_distance(to_tensor(points)), np.float64)

    def _object_scenes(self) -> list[tuple[NDArray[np.float64], NDArray[np.float64],
                                           o3d.t.geometry.RaycastingScene]]:
        """Per object: x/y bounds, top height and a raycasting scene of its triangles alone."""
        if self._objects is None:
            import open3d as o3d

            self._objects = []
            for oid in np.unique(self.object_ids):
                tris = self.triangles[self.object_ids == oid]
                verts = self.vertices[tris.reshape(-1)]
                scene = o3d.t.geometry.RaycastingScene()
                scene.add_triangles(to_tensor(verts),
                                    to_tensor(np.arange(verts.shape[0]).reshape(-1, 3),
                                              np.uint32))
                self._objects.append((verts.min(0), verts.max(0), scene))
        return self._objects

    def inside(self, points: NDArray[np.float64]) -> NDArray[np.bool_]:
        """True where a point lies inside a solid object (or below an open ground sheet).

        Per object, a near-vertical ray is cast upwards and its crossings with that
        object's triangles counted: an odd count means inside. Counting per object keeps
        the test right where closed objects overlap or touch; an open ground plane counts
        as solid below it. Only points under an object's bounding box are tested.
        """
        points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        out = np.zeros(len(points), dtype=bool)
        by_x = np.argsort(points[:, 0], kind="stable")  # an object's x range: one slice
        xs = points[by_x, 0]
        for lo, hi, scene in self._object_scenes():  # one pass per object, not per point
            rows = by_x[np.searchsorted(xs, lo[0], "left"):np.searchsorted(xs, hi[0], "right")]
            near = points[rows]
            cand = rows[(near[:, 1] >= lo[1]) & (near[:, 1] <= hi[1]) & (near[:, 2] <= hi[2])
                        & ~out[rows]]
            if cand.size == 0:
                continue
            rays = np.hstack([points[cand], np.broadcast_to(_UP, (cand.size, 3))])
            hits = to_array(scene.count_intersections(to_tensor(rays)), np.int64)
            out[cand[(hits % 2) == 1]] = True
        return out

    def top_height(self, xy: NDArray[np.float64], z_start: float | None = None,
                   ) -> NDArray[np.float64]:
        """Height of the highest surface below ``z_start`` at each (x, y); NaN where none."""
        top = float(self.vertices[:, 2].max()) + 1.0 if z_start is None else z_start
        origin = np.column_stack([xy, np.full(len(xy), top)])
        down = np.broadcast_to([0.0, 0.0, -1.0], origin.shape)
        t_hit = to_array(self._scene.cast_rays(to_tensor(np.hstack([origin, down])))["t_hit"],
                         np.float32)
        return np.where(np.isfinite(t_hit), top - t_hit.astype(np.float64), np.nan)
