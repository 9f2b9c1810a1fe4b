"""Map-based ground filter of airborne clouds and its scores (Sithole & Vosselman 2004).

A 2D map (2D-ALTE or Quadtree) gives every point the height of the leaf holding it
(:func:`map_heights`); a raster of ``step`` metres keeps the lowest such height per
pixel, and a grey-scale morphological opening with a ``window`` metre square
(erosion then dilation, NaN-aware) turns it into the map's local minimum-height
surface (:func:`opened_surface`): objects narrower than the window (buildings,
trees) are cut off, planar slopes are kept exactly, except within half a window of
the cloud's edge, where an uphill slope sags by up to slope x window / 2 (the
window is truncated there). A point is ground when it lies
within ``tolerance`` of that surface, above or below (:func:`classify_ground`).
Fed raw point heights instead of leaf heights, the same steps are the classic
morphological filter (Kilian et al. 1996), the baseline a map is judged against.

Scores (:func:`ground_errors`): type I = reference ground rejected / reference
ground, type II = objects accepted as ground / objects, total = misclassified / all,
all in per cent. Everything here takes and returns arrays.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage
from scipy.spatial import cKDTree

from alte.errors import MetricsError, ParameterError
from alte.mappers.base import Cells
from alte.metrics.truth import cell_at_xy

__all__ = ["classify_ground", "ground_errors", "map_heights", "opened_surface",
           "reference_labels"]




def reference_labels(points: NDArray[np.float64], subset: NDArray[np.float64],
                     tolerance: float = 1e-3) -> NDArray[np.bool_]:
    """True for each point of ``points`` found in ``subset`` within ``tolerance`` metres."""
    pts, sub = np.asarray(points, np.float64), np.asarray(subset, np.float64)
    if pts.ndim != 2 or pts.shape[1] != 3 or sub.ndim != 2 or sub.shape[1] != 3:
        raise MetricsError(f"reference labels: points {pts.shape} and subset {sub.shape} "
                           "must both be (N, 3)")
    if len(sub) == 0:
        return np.zeros(len(pts), bool)
    dist, _ = cKDTree(sub).query(pts, distance_upper_bound=tolerance, workers=-1)
    return np.isfinite(dist)


def map_heights(cells: Cells, xy: NDArray[np.float64]) -> NDArray[np.float64]:
    """Height of the 2D map's leaf holding each ``xy`` (NaN: unknown leaf or outside)."""
    idx = cell_at_xy(np.asarray(xy, np.float64)[:, :2], cells.centers, cells.sizes)
    out = np.full(len(idx), np.nan)
    out[idx >= 0] = cells.centers[idx[idx >= 0], 2]
    return out


def opened_surface(xy: NDArray[np.float64], heights: NDArray[np.float64], step: float = 1.0,
                   window: float = 20.0) -> NDArray[np.float64]:
    """Per point: the morphological opening (``window`` m square) of the per-pixel
    (``step`` m) minimum of ``heights``; NaN heights are ignored, NaN where none."""
    if not (np.isfinite(step) and step > 0 and np.isfinite(window) and window >= step):
        raise ParameterError(f"ground filter: step={step} must be > 0 and window={window} "
                             ">= step (metres)")
    xy = np.asarray(xy, np.float64)[:, :2]
    if len(xy) == 0:
        return np.empty(0)
    ij = np.floor((xy - xy.min(axis=0)) / step).astype(np.int64)
    grid = np.full(ij.max(axis=0) + 1, np.inf)
    h = np.asarray(heights, np.float64)
    known = np.isfinite(h)
    np.minimum.at(grid, (ij[known, 0], ij[known, 1]), h[known])
    size = (int(np.ceil(window / step)) | 1,) * 2  # odd: centred on the pixel
    low = ndimage.grey_erosion(grid, size=size, mode="nearest")
    opened = ndimage.grey_dilation(np.where(np.isfinite(low), low, -np.inf), size=size,
                                   mode="nearest")
    out = opened[ij[:, 0], ij[:, 1]]
    return np.where(np.isfinite(out), out, np.nan)


def classify_ground(points: NDArray[np.float64], surface: NDArray[np.float64],
                    tolerance: float) -> NDArray[np.bool_]:
    """Ground = within ``tolerance`` metres of ``surface`` (per point; NaN -> not ground)."""
    if not (np.isfinite(tolerance) and tolerance >= 0):
        raise ParameterError(f"ground filter: tolerance={tolerance} must be >= 0 metres")
    with np.errstate(invalid="ignore"):
        ground: NDArray[np.bool_] = np.abs(np.asarray(points)[:, 2] - surface) <= tolerance
    return ground


def ground_errors(predicted: NDArray[np.bool_], reference: NDArray[np.bool_],
                  ) -> dict[str, float]:
    """Sithole & Vosselman (2004) errors in %: type I (ground rejected / ground), type II
    (objects accepted / objects), total (misclassified / all); NaN for an empty class."""
    pred, ref = np.asarray(predicted, bool), np.asarray(reference, bool)
    if pred.shape != ref.shape or pred.ndim != 1:
        raise MetricsError(f"ground errors: predicted {pred.shape} and reference {ref.shape} "
                           "must be equal 1-D shapes")
    rejected, accepted = int((ref & ~pred).sum()), int((~ref & pred).sum())
    n_ground, n_object = int(ref.sum()), int((~ref).sum())

    def pct(num: int, den: int) -> float:
        return 100.0 * num / den if den else float("nan")

    return {"type_i_pct": pct(rejected, n_ground), "type_ii_pct": pct(accepted, n_object),
            "total_pct": pct(rejected + accepted, len(ref)), "ground_rejected": rejected,
            "objects_accepted": accepted, "reference_ground": n_ground,
            "reference_objects": n_object}


