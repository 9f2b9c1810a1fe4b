"""Truly safe landing centres from the simulator's mesh, and detection scores against them.

The true raster is the top surface under every pixel centre (a vertical ray cast down
the mesh) and the object it belongs to. A pixel is a truly safe centre under the
same tests as a detected one (:func:`alte.lab.studies.landing.detect.feasible_centres`: known,
planar disk, obstacle keep-out) with *obstacle* meaning any pixel overlapped by the
footprint of an object whose class is not ``ground``, however low: a 2 cm block is not
a landing pad. Footprints are the convex hulls of the objects' x/y vertices
(:func:`object_footprints`), tested against whole pixel squares, so objects thinner
than a pixel (fence rails, posts) are never missed between ray positions. So
the truth is at least as strict as the map can be, and low debris the map cannot see
costs precision, as in the thesis' experimental terrains (4.2.3-4.2.4).

Scores (:func:`score_detection`): ``precision`` is the share of chosen sites (the
``max_sites`` best) whose centre disk is truly safe; ``area_precision`` the share of
detected feasible centre area that is truly feasible; ``recall`` the share of truly
feasible centre area detected; ``recall_known`` the same over the truly feasible
area whose disk the map knows (unmapped ground does not count against it).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from scipy.spatial import ConvexHull, QhullError

from alte.errors import MetricsError
from alte.lab.studies.landing.detect import Centres, Detection, feasible_centres
from alte.lab.studies.landing.params import LandingSettings
from alte.lab.studies.landing.raster import RasterGeometry
from alte.metrics import TrueSurface
from alte.tensors import to_array, to_tensor

__all__ = ["GROUND_CLASSES", "object_footprints", "score_detection", "top_surface",
           "truth_centres"]

#: Object classes a vehicle may land on.
GROUND_CLASSES = frozenset({"ground"})


def _hull(xy: NDArray[np.float64]) -> NDArray[np.float64]:
    """Counter-clockwise convex hull of ``xy`` (a segment or point when degenerate)."""
    try:
        return xy[ConvexHull(xy).vertices]
    except QhullError:  # flat in x/y (e.g. a vertical sheet): keep its extreme points
        far = np.argsort(xy @ (xy.max(0) - xy.min(0) + 1e-12))
        return xy[[far[0], far[-1]]]


def _square_overlaps(grid: RasterGeometry, rows: NDArray[np.intp], cols: NDArray[np.intp],
                     hull: NDArray[np.float64]) -> NDArray[np.bool_]:
    """Separating-axis test of the pixel squares (rows, cols) against a convex polygon."""
    xs, ys = grid.axes()
    centers = np.column_stack([xs[cols], ys[rows]])
    edges = np.roll(hull, -1, axis=0) - hull
    normals = np.column_stack([edges[:, 1], -edges[:, 0]])
    normals = normals[np.linalg.norm(normals, axis=1) > 1e-12]
    if not len(normals):
        return np.ones(len(rows), dtype=bool)
    proj_hull = hull @ normals.T  # (vertices, axes)
    reach = 0.5 * grid.step * np.abs(normals).sum(axis=1)
    proj = centers @ normals.T  # (pixels, axes)
    apart = (proj + reach < proj_hull.min(0)) | (proj - reach > proj_hull.max(0))
    overlaps: NDArray[np.bool_] = ~apart.any(axis=1)
    return overlaps


def object_footprints(surface: TrueSurface, grid: RasterGeometry, ids: NDArray[np.int64],
                      ) -> NDArray[np.bool_]:
    """Pixels (ny, nx) whose square overlaps the x/y convex hull of any object in ``ids``."""
    out = np.zeros(grid.shape, dtype=bool)
    for oid in ids:  # one vectorized test per object (tens of them), never per pixel
        verts = surface.vertices[surface.triangles[surface.object_ids == oid].ravel(), :2]
        if not len(verts):
            continue
        hull = _hull(np.unique(verts, axis=0))
        lo, hi = grid.index(np.array([hull.min(0), hull.max(0)]))
        r0, c0 = np.maximum(lo, 0)
        r1, c1 = np.minimum(hi, np.array(grid.shape) - 1)
        if r1 < r0 or c1 < c0:
            continue
        rows, cols = np.meshgrid(np.arange(r0, r1 + 1), np.arange(c0, c1 + 1), indexing="ij")
        hit = _square_overlaps(grid, rows.ravel(), cols.ravel(), hull)
        out[rows.ravel()[hit], cols.ravel()[hit]] = True
    return out


def top_surface(surface: TrueSurface, xy: NDArray[np.float64], z_start: float,
                ) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """Height and object id of the highest surface below ``z_start`` at each (x, y).

    NaN height and id -1 where the ray hits nothing.
    """
    import open3d as o3d  # here, not at the top: importing the landing study costs no open3d

    scene = o3d.t.geometry.RaycastingScene()
    scene.add_triangles(to_tensor(surface.vertices), to_tensor(surface.triangles, np.uint32))
    rays = np.zeros((len(xy), 6), dtype=np.float32)
    rays[:, :2], rays[:, 2], rays[:, 5] = xy, z_start, -1.0
    hit = scene.cast_rays(to_tensor(rays))
    t_hit = to_array(hit["t_hit"], np.float64)
    found = np.isfinite(t_hit)
    prim = to_array(hit["primitive_ids"], np.int64)
    ids = np.where(found, surface.object_ids[np.where(found, prim, 0)], -1)
    return np.where(found, z_start - t_hit, np.nan), ids


def truth_centres(surface: TrueSurface, grid: RasterGeometry, params: LandingSettings,
                  z_start: float) -> Centres:
    """Truly safe centres on ``grid`` (module docstring); rays start at ``z_start``."""
    if not surface.classes:
        raise MetricsError("landing truth: the true surface has no object classes, so the "
                           "ground cannot be told from obstacles")
    height, ids = top_surface(surface, grid.centers(), z_start)
    others = np.array([i for i, c in surface.classes.items() if c not in GROUND_CLASSES])
    obstacle = np.isin(ids, others).reshape(grid.shape) | object_footprints(surface, grid,
                                                                            others)
    return feasible_centres(height.reshape(grid.shape), obstacle, grid.step, params)


def _share(num: int, den: int) -> float:
    return float(num / den) if den else float("nan")


def score_detection(detection: Detection, truth: Centres, params: LandingSettings,
                    ) -> dict[str, float]:
    """Precision of the chosen sites, area precision and recall (module docstring)."""
    true = truth.feasible
    if true.shape != detection.grid.shape:
        raise MetricsError(f"landing truth {true.shape} and detection {detection.grid.shape} "
                           "rasters differ")
    det = detection.centres.feasible
    chosen = detection.chosen
    rc = detection.grid.index(chosen[["x", "y"]].to_numpy())
    safe = true[rc[:, 0], rc[:, 1]] if len(rc) else np.zeros(0, dtype=bool)
    hit = int((det & true).sum())
    map_knows = detection.centres.known_dist > params.disk
    pixel = detection.grid.step**2
    return {
        "sites": len(detection.sites), "chosen": len(chosen),
        "precision": float(safe.mean()) if len(safe) else float("nan"),
        "best_site_safe": bool(safe[0]) if len(safe) else False,
        "area_precision": _share(hit, int(det.sum())),
        "recall": _share(hit, int(true.sum())),
        "recall_known": _share(int((det & true & map_knows).sum()), int((true & map_knows).sum())),
        "detected_area_m2": float(det.sum() * pixel), "safe_area_m2": float(true.sum() * pixel),
        "known_share": float(np.isfinite(detection.height).mean()),
    }
