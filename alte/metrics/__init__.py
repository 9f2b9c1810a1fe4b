"""Map quality metrics: the thesis' (5.2.1) and ground-truth ones from the simulator.

Thesis metrics: elapsed mapping time (measured by the pipeline around the mapper calls
only, repeated and summarised by :mod:`alte.metrics.timing`), number of basis functions
(``Mapper.basis_functions``), and the Hausdorff / modified Hausdorff distances between
the registered cloud and the corners of the occupied cells (:func:`hausdorff`).
Ground-truth metrics (accuracy, completeness, 2D height RMSE and unknown share, Octomap
free-space truth) are defined in :mod:`alte.metrics.truth` and :mod:`alte.metrics.freespace`.
"""

from alte.metrics.freespace import free_space_truth
from alte.metrics.hausdorff import HausdorffResult, directed_distances, hausdorff
from alte.metrics.surface import SurfaceSamples, TrueSurface
from alte.metrics.timing import Timing, log_spread
from alte.metrics.truth import (
    accuracy,
    cell_at_xy,
    completeness,
    completeness_by_class,
    completeness_by_object,
    distance_to_boxes,
    ground_truth_metrics,
    height_metrics_2d,
    seen_mask,
)

__all__ = [
    "HausdorffResult",
    "SurfaceSamples",
    "Timing",
    "TrueSurface",
    "accuracy",
    "cell_at_xy",
    "completeness",
    "completeness_by_class",
    "completeness_by_object",
    "directed_distances",
    "distance_to_boxes",
    "free_space_truth",
    "ground_truth_metrics",
    "hausdorff",
    "height_metrics_2d",
    "log_spread",
    "seen_mask",
]
