"""Metrics against the simulator's ground truth (beyond the thesis, which had none).

Definitions (``tol`` = ``tolerance`` in metres; "occupied" = ``Cells.occupied``):

* **accuracy** (``accuracy_mean_m``, ``accuracy_p95_m``): distance from each occupied
  cell centre (2D maps: every cell with a finite height, as the point x, y, height) to
  the nearest true triangle.
  ``phantom_share``: share of occupied cells that cannot touch any true surface
  (centre distance minus the cell's half diagonal > ``tol``): mapped outliers.
* **completeness** (3D maps): share of true-surface samples (uniform by area, seeded,
  inside the control volume) whose distance to the nearest occupied *box* (not its
  centre) is <= ``tol``; this is the incompleteness measure thesis 5.2.2 asked for.
  ``completeness_seen`` restricts the samples to surfaces the sensor saw (a registered
  point within ``tol``), so it separates mapper losses from unscanned areas.
  ``completeness_by_object`` / ``completeness_by_class`` give the same share per
  labelled object and per object class (e.g. ``overhang``).
* **2D maps** (height in ``centers[:, 2]``): on an x/y grid of step ``grid_step`` over
  the control volume, the true top height comes from a vertical ray cast down the mesh
  and the map height from the cell covering the grid point. ``height_rmse_m`` is the RMSE
  where both exist, ``unknown_share`` the share of grid points no cell with a finite
  height covers, and ``completeness`` the share of grid points whose map height is
  within ``tol`` of the true top (uncovered points count as misses). A map whose cells
  carry a height variance (the ``variance`` layer, :data:`alte.mappers.VARIANCE`) is
  also checked for the calibration of its claimed uncertainty: ``within_2sigma`` is the
  share of the probes covered by a cell with a finite variance whose true height lies
  within two standard deviations of the cell's height (0.954 for a calibrated Gaussian
  sigma; lower: the map claims more certainty than it has), ``sigma_mean_m`` the mean
  sigma over those probes.
* **free space** (maps with free leaves, i.e. Octomap): ``free_truly_free_share`` is
  the volume share of free leaves whose centres lie outside every solid (see
  :meth:`TrueSurface.inside`; estimated from 200 000 volume-weighted leaves when there
  are more); NaN for maps that store no free space.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, TypedDict

import numpy as np
from numpy.typing import NDArray
from scipy.spatial import cKDTree

from alte.errors import MetricsError
from alte.metrics.cellxy import cell_at_xy, size_groups
from alte.metrics.freespace import free_space_truth
from alte.metrics.surface import SurfaceSamples, TrueSurface

if TYPE_CHECKING:
    from alte.mappers.base import Cells

__all__ = [
    "TruthValues",
    "accuracy",
    "accuracy_of",
    "cell_at_xy",
    "check_truth_args",
    "completeness",
    "completeness_by_class",
    "completeness_by_object",
    "distance_to_boxes",
    "ground_truth_metrics",
    "height_metrics_2d",
    "height_summary",
    "probe_grid",
    "probe_sigma",
    "seen_mask",
    "size_groups",
]


class TruthValues(TypedDict, total=False):
    """Ground-truth metrics by name (module docstring), as
    :class:`~alte.metrics.maps.TruthMetrics` takes them; each function gives its own."""

    accuracy_mean_m: float
    accuracy_p95_m: float
    phantom_share: float
    completeness: float
    completeness_seen: float
    seen_share: float
    height_rmse_m: float
    unknown_share: float
    within_2sigma: float
    sigma_mean_m: float
    free_truly_free_share: float
    completeness_by_class: dict[str, float]
    completeness_by_object: dict[str, float]


def distance_to_boxes(points: NDArray[np.float64], centers: NDArray[np.float64],
                      sizes: NDArray[np.float64], max_distance: float) -> NDArray[np.float64]:
    """Distance from each point to the nearest axis-aligned box; inf beyond ``max_distance``.

    Cells are grouped by size; in each group a KD-tree on the centres finds every box
    that may lie within ``max_distance`` (centre within half diagonal + max_distance)
    and the exact point-to-box distance is taken over those candidate pairs.
    """
    out = np.full(len(points), np.inf)
    if len(points) == 0 or len(centers) == 0:
        return out
    half = np.asarray(sizes, dtype=np.float64) / 2.0
    groups, inverse = size_groups(half)
    point_tree = cKDTree(points)
    for g, h in enumerate(groups):
        sel = np.flatnonzero(inverse.reshape(-1) == g)
        radius = float(np.linalg.norm(h)) + max_distance
        pairs = point_tree.sparse_distance_matrix(cKDTree(centers[sel]), radius,
                                                  output_type="ndarray")
        if len(pairs) == 0:
            continue
        i, j = pairs["i"], sel[pairs["j"]]
        gap = np.maximum(np.abs(points[i] - centers[j]) - h, 0.0)
        np.minimum.at(out, i, np.linalg.norm(gap, axis=1))
    out[out > max_distance] = np.inf
    return out


def accuracy(centers: NDArray[np.float64], sizes: NDArray[np.float64], surface: TrueSurface,
             tolerance: float) -> TruthValues:
    """Mean / 95th percentile centre-to-surface distance and the phantom-cell share."""
    if len(centers) == 0:
        return accuracy_of(np.empty(0), sizes, tolerance)
    return accuracy_of(surface.distance(centers), sizes, tolerance)


def accuracy_of(dist: NDArray[np.float64], sizes: NDArray[np.float64], tolerance: float,
                ) -> TruthValues:
    """:func:`accuracy` from the cells' centre distances ``dist`` and their ``sizes``."""
    if len(dist) == 0:
        return {"accuracy_mean_m": np.nan, "accuracy_p95_m": np.nan, "phantom_share": np.nan}
    half_diag = np.linalg.norm(sizes, axis=1) / 2.0
    return {
        "accuracy_mean_m": float(dist.mean()),
        "accuracy_p95_m": float(np.percentile(dist, 95)),
        "phantom_share": float(np.mean(dist - half_diag > tolerance)),
    }


def completeness(samples: SurfaceSamples, centers: NDArray[np.float64],
                 sizes: NDArray[np.float64], tolerance: float) -> NDArray[np.bool_]:
    """Per sample: True when an occupied box lies within ``tolerance`` of it."""
    covered: NDArray[np.bool_] = np.isfinite(
        distance_to_boxes(samples.points, centers, sizes, tolerance))
    return covered


def completeness_by_object(samples: SurfaceSamples, covered: NDArray[np.bool_],
                           labels: dict[int, str]) -> dict[str, float]:
    """Share of covered samples per object id, keyed by label (or ``object_<id>``)."""
    out = {}
    for oid in np.unique(samples.object_ids):
        mask = samples.object_ids == oid
        out[labels.get(int(oid), f"object_{int(oid)}")] = float(covered[mask].mean())
    return out


def completeness_by_class(samples: SurfaceSamples, covered: NDArray[np.bool_],
                          classes: dict[int, str]) -> dict[str, float]:
    """Share of covered samples per object class (objects without a class are skipped)."""
    names = sorted(set(classes.values()))
    ids = np.unique(samples.object_ids)
    lut = {int(i): names.index(classes[int(i)]) for i in ids if int(i) in classes}
    per_sample = np.full(len(samples), -1)
    for oid, cls in lut.items():  # one pass per object, not per point
        per_sample[samples.object_ids == oid] = cls
    return {names[c]: float(covered[per_sample == c].mean()) for c in np.unique(per_sample)
            if c >= 0}


def seen_mask(samples: SurfaceSamples, cloud: NDArray[np.float64], tolerance: float,
              ) -> NDArray[np.bool_]:
    """True for samples with a registered point within ``tolerance`` (surfaces the sensor saw)."""
    if len(cloud) == 0:
        return np.zeros(len(samples), dtype=bool)
    dist, _ = cKDTree(cloud).query(samples.points, k=1, distance_upper_bound=tolerance,
                                   workers=-1)
    return np.isfinite(dist)


def height_metrics_2d(cells: Cells, surface: TrueSurface, bounds: NDArray[np.float64],
                      grid_step: float, tolerance: float) -> TruthValues:
    """Height RMSE, unknown share and completeness of a 2D map on an x/y grid (see module)."""
    xy = probe_grid(bounds, grid_step)
    known = np.isfinite(cells.centers[:, 2])
    idx = cell_at_xy(xy, cells.centers[known], cells.sizes[known])
    map_h = np.where(idx >= 0, cells.centers[known][np.maximum(idx, 0), 2], np.nan)
    true_h = surface.top_height(xy, z_start=float(bounds[1][2]))
    return height_summary(idx, map_h, true_h, tolerance, probe_sigma(cells, known, idx))


def probe_sigma(cells: Cells, known: NDArray[np.bool_], idx: NDArray[np.int64],
                ) -> NDArray[np.float64] | None:
    """Each probe's height sigma: the square root of the ``variance`` layer of the known
    cell ``idx`` covering it (NaN where none does); None for a map without the layer."""
    from alte.mappers.base import VARIANCE

    variance = cells.layer(VARIANCE)
    if variance is None:
        return None
    var = np.asarray(variance, dtype=np.float64)[known]
    sigma = np.sqrt(np.where(var >= 0, var, np.nan)) if len(var) else np.empty(0)
    return np.where(idx >= 0, sigma[np.maximum(idx, 0)] if len(sigma) else np.nan, np.nan)


def probe_grid(bounds: NDArray[np.float64], grid_step: float) -> NDArray[np.float64]:
    """The x/y probes of the 2D metrics: a grid of step ``grid_step`` over ``bounds``."""
    lo, hi = bounds
    xs = np.arange(lo[0] + grid_step / 2, hi[0], grid_step)
    ys = np.arange(lo[1] + grid_step / 2, hi[1], grid_step)
    if len(xs) == 0 or len(ys) == 0:
        raise MetricsError(f"2D metrics: grid_step={grid_step} leaves no grid in bounds {bounds}")
    return np.stack(np.meshgrid(xs, ys, indexing="xy"), axis=-1).reshape(-1, 2)


def height_summary(idx: NDArray[np.int64], map_h: NDArray[np.float64],
                   true_h: NDArray[np.float64], tolerance: float,
                   sigma: NDArray[np.float64] | None = None) -> TruthValues:
    """The 2D metrics from each probe's cell (-1: none), map height and true height, and
    with each probe's claimed ``sigma`` (:func:`probe_sigma`) its calibration."""
    has_truth = np.isfinite(true_h)
    both = has_truth & (idx >= 0)
    err = map_h[both] - true_h[both]
    out: TruthValues = {
        "height_rmse_m": float(np.sqrt(np.mean(err**2))) if err.size else np.nan,
        "unknown_share": float(np.mean(idx < 0)),
        "completeness": float(np.mean(np.abs(map_h[has_truth] - true_h[has_truth]) <= tolerance))
        if has_truth.any() else np.nan,
    }
    if sigma is not None:
        claimed = both & np.isfinite(sigma) & np.isfinite(map_h)
        miss = np.abs(map_h[claimed] - true_h[claimed])
        out["within_2sigma"] = (float(np.mean(miss <= 2.0 * sigma[claimed])) if claimed.any()
                                else np.nan)
        out["sigma_mean_m"] = float(np.mean(sigma[claimed])) if claimed.any() else np.nan
    return out


def check_truth_args(dims: int, tolerance: float) -> None:
    """Raise :class:`MetricsError` unless ``dims`` is 2 or 3 and ``tolerance`` > 0."""
    if dims not in (2, 3):
        raise MetricsError(f"ground-truth metrics: dims must be 2 or 3, got {dims}")
    if tolerance <= 0:
        raise MetricsError(f"ground-truth metrics: tolerance must be > 0, got {tolerance}")


def ground_truth_metrics(cells: Cells, surface: TrueSurface, *, dims: int,
                         cloud: NDArray[np.float64], bounds: NDArray[np.float64] | None = None,
                         tolerance: float = 0.2, n_samples: int = 100_000,
                         grid_step: float = 0.2, seed: int = 0) -> TruthValues:
    """Every ground-truth metric of one map (definitions in the module docstring).

    ``cloud`` is the registered cloud (for ``completeness_seen``); ``bounds`` (2, 3) the
    control volume (default: the mesh's bounding box).
    """
    check_truth_args(dims, tolerance)
    box = np.array([surface.vertices.min(0), surface.vertices.max(0)]) if bounds is None \
        else np.asarray(bounds, dtype=np.float64)
    finite = np.isfinite(cells.centers).all(axis=1)
    # 2D maps: every cell with a height is part of the surface estimate, obstacle or not.
    occ = finite if dims == 2 else finite & cells.occupied.astype(bool)
    out = accuracy(cells.centers[occ], cells.sizes[occ], surface, tolerance)
    if dims == 2:
        out.update(height_metrics_2d(cells, surface, box, grid_step, tolerance))
        return out
    samples = surface.sample(n_samples, seed=seed, bounds=box)
    covered = completeness(samples, cells.centers[occ], cells.sizes[occ], tolerance)
    seen = seen_mask(samples, np.asarray(cloud, dtype=np.float64).reshape(-1, 3), tolerance)
    out["completeness"] = float(covered.mean()) if len(samples) else np.nan
    out["completeness_seen"] = float(covered[seen].mean()) if seen.any() else np.nan
    out["seen_share"] = float(seen.mean()) if len(samples) else np.nan
    out["completeness_by_object"] = completeness_by_object(samples, covered, surface.labels)
    if surface.classes:
        out["completeness_by_class"] = completeness_by_class(samples, covered, surface.classes)
    out["free_truly_free_share"] = free_space_truth(cells, surface, seed=seed)
    return out
