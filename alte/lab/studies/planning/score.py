"""Paths scored against the simulator's true mesh: clearance violations and collisions.

A planned path is only as safe as the map it was planned on. Here it is sampled
densely and every sample is checked against the ground-truth surface: its distance
to the nearest true triangle (``TrueSurface.distance``) and whether it lies inside a
solid object (``TrueSurface.inside``). A sample *collides* when it is inside a solid
or closer than the clearance radius; each sample carries the length of path it
stands for, so the colliding length is in metres.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from alte.errors import MetricsError
from alte.metrics import TrueSurface

__all__ = ["PathScore", "densify", "score_path"]


@dataclass(frozen=True)
class PathScore:
    """Collision figures of one path (NaN / 0 for an empty path)."""

    samples: int
    colliding_samples: int
    inside_samples: int
    colliding_length_m: float
    min_clearance_m: float

    def as_dict(self) -> dict[str, float | int]:
        return {"samples": self.samples, "colliding_samples": self.colliding_samples,
                "inside_samples": self.inside_samples,
                "colliding_length_m": self.colliding_length_m,
                "min_clearance_m": self.min_clearance_m}


def densify(path: NDArray[np.float64], spacing: float,
            ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Samples at most ``spacing`` apart along a polyline, and the length each stands for."""
    if not (np.isfinite(spacing) and spacing > 0):
        raise MetricsError(f"path sampling spacing={spacing!r} must be > 0 (m)")
    path = np.asarray(path, dtype=np.float64)
    if path.ndim != 2 or path.shape[1] != 3 or len(path) < 2:
        raise MetricsError(f"path must be (M >= 2, 3) points, got {path.shape}")
    seg = np.diff(path, axis=0)
    lengths = np.linalg.norm(seg, axis=1)
    counts = np.maximum(np.ceil(lengths / spacing).astype(np.int64), 1)
    seg_id = np.repeat(np.arange(len(seg)), counts)
    first = np.repeat(np.cumsum(counts) - counts, counts)
    t = (np.arange(counts.sum()) - first) / counts[seg_id]
    samples = np.vstack([path[seg_id] + t[:, None] * seg[seg_id], path[-1:]])
    weights = np.append(lengths[seg_id] / counts[seg_id], 0.0)
    return samples, weights


def score_path(path: NDArray[np.float64], surface: TrueSurface, clearance: float,
               spacing: float | None = None) -> PathScore:
    """Collisions of ``path`` with the true mesh; ``spacing`` defaults to clearance / 4.

    ``min_clearance_m`` is the smallest sample distance to the mesh, 0 if any sample
    is inside a solid.
    """
    if not (np.isfinite(clearance) and clearance >= 0):
        raise MetricsError(f"clearance={clearance!r} must be >= 0 (m)")
    if len(path) == 0:
        return PathScore(0, 0, 0, float("nan"), float("nan"))
    step = spacing if spacing is not None else (clearance / 4 if clearance > 0 else 0.05)
    samples, weights = densify(path, step)
    dist = surface.distance(samples)
    inside = surface.inside(samples)
    bad = inside | (dist < clearance)
    min_clear = 0.0 if inside.any() else float(dist.min())
    return PathScore(len(samples), int(bad.sum()), int(inside.sum()),
                     float(weights[bad].sum()), min_clear)
