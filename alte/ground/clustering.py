"""Euclidean clustering (thesis 2.1.4) and the obstacle map of thesis 3.3.1 (fig. 3.13).

Two points belong to the same cluster when a chain of points links them with
steps no longer than ``tolerance``: the connected components of the graph of
point pairs within ``tolerance`` (found with a k-d tree). The obstacle map
summarises each cluster by centroid and radius, the circles a path planner avoids.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from alte.errors import ParameterError
from alte.ground.plane import PlaneFit, height_above
from alte.types import as_points

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["OBSTACLE_COLUMNS", "euclidean_clusters", "obstacle_map"]

#: Columns of :func:`obstacle_map`, one row per cluster.
OBSTACLE_COLUMNS = (
    "label", "n_points", "x", "y", "z", "radius",
    "xmin", "ymin", "zmin", "xmax", "ymax", "zmax", "height",
)


def _check(points: object, owner: str) -> NDArray[np.float64]:
    return as_points(points, owner=owner, error=ParameterError, finite=True)


def euclidean_clusters(
    points: NDArray[np.float64], tolerance: float, min_size: int = 1, max_size: int | None = None
) -> NDArray[np.int64]:
    """Label every point with its cluster (N,) int64; -1 for clusters outside the size range.

    Clusters are numbered 0, 1, ... by decreasing size (ties: the cluster holding
    the lowest point index first), so the labels are deterministic.
    """
    pts = _check(points, "euclidean_clusters")
    if not np.isfinite(tolerance) or tolerance <= 0:
        raise ParameterError(f"euclidean_clusters: tolerance={tolerance!r} must be > 0")
    if min_size < 1:
        raise ParameterError(f"euclidean_clusters: min_size={min_size!r} must be >= 1")
    if max_size is not None and max_size < min_size:
        raise ParameterError(
            f"euclidean_clusters: max_size={max_size!r} is below min_size={min_size!r}"
        )
    n = len(pts)
    if n == 0:
        return np.empty(0, np.int64)
    pairs = cKDTree(pts).query_pairs(float(tolerance), output_type="ndarray")
    graph = coo_matrix((np.ones(len(pairs), np.int8), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    _count, comp = connected_components(graph, directed=False)
    sizes = np.bincount(comp)
    first = np.full(len(sizes), n)
    np.minimum.at(first, comp, np.arange(n))
    order = np.lexsort((first, -sizes))
    valid = sizes[order] >= min_size
    if max_size is not None:
        valid &= sizes[order] <= max_size
    relabel = np.full(len(sizes), -1, np.int64)
    relabel[order[valid]] = np.arange(int(valid.sum()))
    return relabel[comp]


def _ground_height(
    pts: NDArray[np.float64], starts: NDArray[np.intp],
    ground: PlaneFit | float | NDArray[np.float64] | None,
) -> NDArray[np.float64]:
    """Top of each cluster above the ground plane, the bare earth under each point, a
    ground level, or its own bottom."""
    if isinstance(ground, PlaneFit):
        return np.maximum.reduceat(height_above(pts, ground), starts)
    if isinstance(ground, np.ndarray) and ground.ndim == 1:
        return np.maximum.reduceat(pts[:, 2] - ground, starts)
    top = np.maximum.reduceat(pts[:, 2], starts)
    if ground is None:
        return top - np.minimum.reduceat(pts[:, 2], starts)
    if not np.isfinite(ground):
        raise ParameterError(f"obstacle_map: ground={ground!r} must be finite")
    return top - float(ground)


def obstacle_map(
    points: NDArray[np.float64], labels: ArrayLike,
    ground: PlaneFit | float | NDArray[np.float64] | None = None,
) -> pd.DataFrame:
    """One row per cluster: size, centroid, radius, bounding box and height (thesis fig. 3.13).

    ``radius`` is the largest horizontal distance from the centroid to a point of
    the cluster. ``height`` is measured from ``ground`` (a fitted plane, the bare-earth
    height under every point as a ground filter gives it, or a ground level z), or from
    the cluster's lowest point when no ground is given. Points labelled -1 are ignored.
    """
    import pandas as pd  # on first use: the ground package is on ``alte map``'s path

    pts = _check(points, "obstacle_map")
    lab = np.asarray(labels).reshape(-1)
    if lab.shape[0] != len(pts) or not np.issubdtype(lab.dtype, np.integer):
        raise ParameterError(
            f"obstacle_map: labels must be {len(pts)} integers, got {lab.shape} {lab.dtype}"
        )
    keep = lab >= 0
    if isinstance(ground, np.ndarray) and ground.ndim == 1:
        if len(ground) != len(keep):
            raise ParameterError(f"obstacle_map: ground must be {len(keep)} heights, got "
                                 f"{ground.shape}")
        ground = np.asarray(ground, np.float64)[keep]
    pts, lab = pts[keep], lab[keep]
    if len(lab) == 0:
        return pd.DataFrame({name: [] for name in OBSTACLE_COLUMNS})
    order = np.argsort(lab, kind="stable")
    pts, lab = pts[order], lab[order]
    if isinstance(ground, np.ndarray) and ground.ndim == 1:
        ground = ground[order]
    starts = np.flatnonzero(np.r_[True, lab[1:] != lab[:-1]])
    counts = np.diff(np.r_[starts, len(lab)])
    centroid = np.add.reduceat(pts, starts, axis=0) / counts[:, None]
    offset = pts[:, :2] - np.repeat(centroid[:, :2], counts, axis=0)
    radius = np.sqrt(np.maximum.reduceat(np.einsum("ij,ij->i", offset, offset), starts))
    low, high = np.minimum.reduceat(pts, starts, axis=0), np.maximum.reduceat(pts, starts, axis=0)
    columns = [lab[starts], counts, *centroid.T, radius, *low.T, *high.T]
    columns.append(_ground_height(pts, starts, ground))
    return pd.DataFrame(dict(zip(OBSTACLE_COLUMNS, columns, strict=True)))
