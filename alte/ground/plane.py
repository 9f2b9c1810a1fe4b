"""Ground plane fitting with MSAC (thesis 2.1.4) and height above it.

MSAC (Torr & Zisserman 2000) is RANSAC scored with a truncated quadratic:
``cost = sum(min(r^2, t^2))``, so inliers count by how well they fit and not just
by being within ``t``. Candidate planes are drawn in batches and all scored at
once with one matrix product (memory bounded by :data:`_MAX_ELEMENTS`); the
number of draws adapts to the best inlier ratio seen so far, and the winner is
refined by least squares (SVD) on its inliers.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from alte.errors import GroundError, ParameterError
from alte.types import as_points

__all__ = [
    "PlaneFit",
    "fit_plane_msac",
    "fit_plane_open3d",
    "height_above",
    "obstacle_mask",
]

#: Largest residual matrix (points x candidates) scored at once: 32 MB of float64.
_MAX_ELEMENTS = 1 << 22
_BATCH = 256


@dataclass(frozen=True)
class PlaneFit:
    """Plane ``normal . p + d = 0`` with a unit normal pointing up (z >= 0).

    ``inliers`` (N,) marks points closer than the threshold, ``cost`` is the MSAC
    cost of the plane and ``iterations`` how many candidate planes were drawn.
    """

    normal: NDArray[np.float64]
    d: float
    inliers: NDArray[np.bool_]
    cost: float
    iterations: int = 0


def _check_cloud(points: object, owner: str) -> NDArray[np.float64]:
    arr = as_points(points, owner=owner, error=ParameterError, finite=True)
    if len(arr) < 3:
        raise GroundError(f"{owner}: a plane needs at least 3 points, got {len(arr)}")
    return arr


def _trials(inlier_ratio: float, confidence: float) -> float:
    """Draws needed to pick an all-inlier triple with ``confidence``."""
    good = inlier_ratio**3
    if good >= 1.0:
        return 1.0
    if good <= 0.0:
        return np.inf
    return float(np.ceil(np.log1p(-confidence) / np.log1p(-good)))


def _candidates(
    pts: NDArray[np.float64], idx: NDArray[np.int64], reference: NDArray[np.float64] | None,
    min_cos: float,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Unit normals (K, 3) and offsets (K,) of the usable triples in ``idx``.

    Collinear or repeated triples are dropped, and so are planes tilted more than
    the allowed angle from ``reference`` (either orientation).
    """
    a, b, c = pts[idx[:, 0]], pts[idx[:, 1]], pts[idx[:, 2]]
    normals = np.cross(b - a, c - a)
    length = np.linalg.norm(normals, axis=1)
    scale = max(1.0, float(np.abs(pts).max()))
    keep = length > 1e-12 * scale * scale
    normals = normals[keep] / length[keep, None]
    a = a[keep]
    if reference is not None:
        tilt_ok = np.abs(normals @ reference) >= min_cos
        normals, a = normals[tilt_ok], a[tilt_ok]
    return normals, -np.einsum("ij,ij->i", normals, a)


def _search(
    pts: NDArray[np.float64],
    *,
    threshold: float,
    max_iterations: int,
    confidence: float,
    rng: np.random.Generator,
    constraint: tuple[NDArray[np.float64] | None, float],
) -> tuple[NDArray[np.float64] | None, float, int]:
    """Best (normal, d) by MSAC cost over adaptively many random triples; also draws made."""
    n, t2 = len(pts), threshold * threshold
    batch = int(max(1, min(_BATCH, _MAX_ELEMENTS // n)))
    needed, drawn = float(max_iterations), 0
    best_cost, best = np.inf, None
    while drawn < needed:
        k = int(min(batch, needed - drawn))
        normals, offsets = _candidates(pts, rng.integers(0, n, size=(k, 3)), *constraint)
        drawn += k
        if len(normals) == 0:
            continue
        sq = (pts @ normals.T + offsets) ** 2
        costs = np.minimum(sq, t2).sum(axis=0)
        j = int(np.argmin(costs))
        if costs[j] < best_cost:
            best_cost, best = float(costs[j]), np.r_[normals[j], offsets[j]]
            ratio = np.count_nonzero(sq[:, j] < t2) / n
            needed = min(float(max_iterations), _trials(ratio, confidence))
    return best, best_cost, drawn


def _refine(pts: NDArray[np.float64], model: NDArray[np.float64], threshold: float,
            ) -> NDArray[np.float64]:
    """Least-squares plane (SVD) through the inliers of ``model``."""
    inliers = pts[np.abs(pts @ model[:3] + model[3]) < threshold]
    if len(inliers) < 3:
        return model
    mean = inliers.mean(axis=0)
    normal = np.linalg.svd(inliers - mean, full_matrices=False)[2][-1]
    refined: NDArray[np.float64] = np.r_[normal, -normal @ mean]
    return refined


def _msac_cost(pts: NDArray[np.float64], model: NDArray[np.float64], threshold: float) -> float:
    return float(np.minimum((pts @ model[:3] + model[3]) ** 2, threshold**2).sum())


def _finish(pts: NDArray[np.float64], model: NDArray[np.float64], threshold: float,
            drawn: int) -> PlaneFit:
    """Orient the normal up and score the plane on the original points."""
    normal, d = model[:3] / np.linalg.norm(model[:3]), model[3] / np.linalg.norm(model[:3])
    if normal[2] < 0:
        normal, d = -normal, -d
    dist = pts @ normal + d
    return PlaneFit(
        normal=normal,
        d=float(d),
        inliers=np.abs(dist) < threshold,
        cost=float(np.minimum(dist**2, threshold**2).sum()),
        iterations=drawn,
    )


def _check_fit_params(
    threshold: float, max_iterations: int, confidence: float,
    reference_normal: object, max_angle_deg: float | None,
) -> tuple[NDArray[np.float64] | None, float]:
    """Validate MSAC parameters; return the (unit reference, min |cos|) constraint."""
    if not np.isfinite(threshold) or threshold <= 0:
        raise ParameterError(f"fit_plane_msac: threshold={threshold!r} must be > 0")
    if int(max_iterations) < 1:
        raise ParameterError(f"fit_plane_msac: max_iterations={max_iterations!r} must be >= 1")
    if not 0 < confidence < 1:
        raise ParameterError(f"fit_plane_msac: confidence={confidence!r} must be in (0, 1)")
    if (reference_normal is None) != (max_angle_deg is None):
        raise ParameterError(
            "fit_plane_msac: reference_normal and max_angle_deg must be given together"
        )
    if reference_normal is None or max_angle_deg is None:
        return None, 0.0
    ref = np.asarray(reference_normal, dtype=np.float64).reshape(-1)
    norm = float(np.linalg.norm(ref)) if ref.shape == (3,) else 0.0
    if not np.isfinite(norm) or norm < 1e-12:
        raise ParameterError(f"fit_plane_msac: reference_normal={ref.tolist()} is not a 3-vector")
    if not 0 <= max_angle_deg <= 90:
        raise ParameterError(f"fit_plane_msac: max_angle_deg={max_angle_deg!r} not in [0, 90]")
    return ref / norm, float(np.cos(np.radians(max_angle_deg)))


def fit_plane_msac(
    points: NDArray[np.float64],
    *,
    threshold: float = 0.1,
    max_iterations: int = 1000,
    confidence: float = 0.99,
    seed: int | None = 0,
    reference_normal: NDArray[np.float64] | None = None,
    max_angle_deg: float | None = None,
) -> PlaneFit:
    """Fit the dominant plane (the ground) with MSAC, MATLAB ``pcfitplane``-style.

    ``threshold`` is the inlier distance (m); ``reference_normal`` with
    ``max_angle_deg`` restricts candidates to planes that tilt at most that much
    (e.g. ``(0, 0, 1)``, 10 for near-horizontal ground). Seeded: same input, same fit.
    """
    constraint = _check_fit_params(
        threshold, max_iterations, confidence, reference_normal, max_angle_deg
    )
    pts = _check_cloud(points, "fit_plane_msac")
    center = pts.mean(axis=0)
    local = pts - center
    rng = np.random.default_rng(seed)
    best, cost, drawn = _search(
        local, threshold=threshold, max_iterations=int(max_iterations),
        confidence=confidence, rng=rng, constraint=constraint,
    )
    if best is None:
        raise GroundError(
            f"fit_plane_msac: no valid plane among {drawn} samples of {len(pts)} points "
            "(points collinear/coincident, or no plane within max_angle_deg of reference_normal)"
        )
    refined = _refine(local, best, threshold)
    ref, min_cos = constraint
    tilt_ok = ref is None or abs(refined[:3] @ ref) >= min_cos
    if tilt_ok and _msac_cost(local, refined, threshold) <= cost:
        best = refined
    return _finish(pts, np.r_[best[:3], best[3] - best[:3] @ center], threshold, drawn)


def fit_plane_open3d(
    points: NDArray[np.float64], threshold: float = 0.1, *, max_iterations: int = 1000,
    seed: int = 0,
) -> PlaneFit:
    """The same fit with Open3D's RANSAC ``segment_plane``, for comparison."""
    import open3d as o3d

    if not np.isfinite(threshold) or threshold <= 0:
        raise ParameterError(f"fit_plane_open3d: threshold={threshold!r} must be > 0")
    pts = _check_cloud(points, "fit_plane_open3d")
    o3d.utility.random.seed(int(seed))
    cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(pts))
    model, _inliers = cloud.segment_plane(float(threshold), 3, int(max_iterations))
    model = np.asarray(model, dtype=np.float64).reshape(4)
    if not np.isfinite(model).all() or np.linalg.norm(model[:3]) < 1e-12:
        raise GroundError(f"fit_plane_open3d: Open3D found no plane in {len(pts)} points")
    return _finish(pts, model, threshold, int(max_iterations))


def height_above(points: NDArray[np.float64], plane: PlaneFit) -> NDArray[np.float64]:
    """Signed distance of every point to the plane (N,), positive above (normal side)."""
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    height: NDArray[np.float64] = pts @ plane.normal + plane.d
    return height


def obstacle_mask(points: NDArray[np.float64], plane: PlaneFit, height: float = 0.3,
                  ) -> NDArray[np.bool_]:
    """Points higher than ``height`` above the ground plane: the obstacles (thesis 3.3.1)."""
    if not np.isfinite(height):
        raise ParameterError(f"obstacle_mask: height={height!r} must be finite")
    return height_above(points, plane) > height
