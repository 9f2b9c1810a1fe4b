"""Map-based ground and its scores (Sithole & Vosselman 2004).

A 2D map (2D-ALTE or Quadtree) gives every point the height of the leaf holding it
(:func:`map_heights`); the ground filter (:mod:`alte.ground.filters`) run on those
heights gives the map's bare earth, against which the raw points are judged with the
filter's own tolerance, the same filter as on the raw points (the baseline a map is
judged against). :func:`opened_surface` and :func:`classify_ground`, the morphological
baseline's two steps, live in :mod:`alte.ground.filters` and are re-exported here.

Scores (:func:`ground_errors`): type I = reference ground rejected / reference
ground, type II = objects accepted as ground / objects, total = misclassified / all,
all in per cent, and Cohen's kappa. Everything here takes and returns arrays.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from scipy.spatial import cKDTree

from alte.errors import MetricsError
from alte.ground.filters import classify_ground, opened_surface
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


def _kappa(pred: NDArray[np.bool_], ref: NDArray[np.bool_]) -> float:
    """Cohen's kappa in %: agreement beyond what the two shares give by chance."""
    n = len(ref)
    if n == 0:
        return float("nan")
    observed = float(np.mean(pred == ref))
    p_pred, p_ref = float(pred.mean()), float(ref.mean())
    chance = p_pred * p_ref + (1 - p_pred) * (1 - p_ref)
    return 100.0 * (observed - chance) / (1 - chance) if chance < 1 else float("nan")


def ground_errors(predicted: NDArray[np.bool_], reference: NDArray[np.bool_],
                  ) -> dict[str, float]:
    """Sithole & Vosselman (2004) errors in %: type I (ground rejected / ground), type II
    (objects accepted / objects), total (misclassified / all), and Cohen's kappa (the
    agreement the field reports beside them); NaN for an empty class."""
    pred, ref = np.asarray(predicted, bool), np.asarray(reference, bool)
    if pred.shape != ref.shape or pred.ndim != 1:
        raise MetricsError(f"ground errors: predicted {pred.shape} and reference {ref.shape} "
                           "must be equal 1-D shapes")
    rejected, accepted = int((ref & ~pred).sum()), int((~ref & pred).sum())
    n_ground, n_object = int(ref.sum()), int((~ref).sum())

    def pct(num: int, den: int) -> float:
        return 100.0 * num / den if den else float("nan")

    return {"type_i_pct": pct(rejected, n_ground), "type_ii_pct": pct(accepted, n_object),
            "total_pct": pct(rejected + accepted, len(ref)), "kappa_pct": _kappa(pred, ref),
            "ground_rejected": rejected,
            "objects_accepted": accepted, "reference_ground": n_ground,
            "reference_objects": n_object}


