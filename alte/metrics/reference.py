"""What every map of one input is measured against, prepared once for all of them.

A sweep measures hundreds of maps of one terrain and seed against the same registered
cloud and the same true surface; :func:`alte.metrics.maps.measure_map` alone redoes, per
map, the work those share. A :class:`Reference` does it once:

* set A of HD/MHD, the cloud, validated and bucketed into its nearest-neighbour grids
  (:class:`~alte.metrics.nearest.NearestIndex`);
* the truth for one :class:`~alte.metrics.maps.TruthSettings`: the surface samples, which
  of them the sensor saw (a KD-tree query of the whole cloud) and a KD-tree over them
  (3D maps); the x/y probe grid and the true top height under each probe (2D maps);
* per leaf geometry (the cells' centres and sizes), what the truth says of each leaf:
  its centre's distance to the surface, whether its centre is inside a solid, the
  samples within the tolerance of its box; computed for the leaves a map asks about and
  kept for the next map with the same leaves (a map re-read with another occupancy rule,
  or measured again with another set B), so that map pays for the reductions only.

Every value equals :func:`~alte.metrics.truth.ground_truth_metrics`' and
:func:`~alte.metrics.hausdorff.hausdorff`'s: the per-point computations are the same
calls on the same points (each point's result does not depend on the others in a
call), and the reductions run over the same values in the same order.
"""

from __future__ import annotations

import functools
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray
from scipy.spatial import cKDTree

from alte.metrics.hausdorff import HausdorffResult, _as_set, summarise
from alte.metrics.leaves import LeafTruth
from alte.metrics.nearest import NearestIndex
from alte.metrics.options import GroundTruth, TruthSettings
from alte.metrics.truth import (
    TruthValues,
    cell_at_xy,
    completeness_by_class,
    completeness_by_object,
    probe_grid,
    seen_mask,
)
from alte.types import rows_all

if TYPE_CHECKING:
    from alte.mappers.base import Cells
    from alte.metrics.surface import SurfaceSamples, TrueSurface

__all__ = ["Reference"]

#: Leaves of the geometries a reference keeps per-leaf truth for (about 100 bytes each).
LEAF_BUDGET = 8_000_000


class _Shared:
    """What a :class:`Reference` prepares, each part on first use; its
    :meth:`~Reference.fresh` copies share one."""

    def __init__(self, cloud: NDArray[np.float64], truth: GroundTruth | None,
                 options: TruthSettings) -> None:
        self.cloud, self.truth, self.options = cloud, truth, options

    def ground_truth(self) -> GroundTruth:
        if self.truth is None:
            from alte.errors import MetricsError

            raise MetricsError("reference: made without a ground truth")
        return self.truth

    @functools.cached_property
    def set_a(self) -> NDArray[np.float64]:
        return _as_set(self.cloud, "A")

    @functools.cached_property
    def cloud_index(self) -> NearestIndex:
        return NearestIndex(self.set_a)

    @functools.cached_property
    def box(self) -> NDArray[np.float64]:
        return np.asarray(self.ground_truth().bounds.array(), dtype=np.float64)

    @functools.cached_property
    def samples(self) -> SurfaceSamples:
        o = self.options
        return self.ground_truth().surface.sample(o.n_samples, seed=o.seed, bounds=self.box)

    @functools.cached_property
    def seen(self) -> NDArray[np.bool_]:
        cloud = np.asarray(self.cloud, dtype=np.float64).reshape(-1, 3)
        return seen_mask(self.samples, cloud, self.options.tolerance)

    @functools.cached_property
    def sample_tree(self) -> cKDTree:
        return cKDTree(self.samples.points)

    @functools.cached_property
    def probes(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        xy = probe_grid(self.box, self.options.grid_step)
        return xy, self.ground_truth().surface.top_height(xy, z_start=float(self.box[1, 2]))


class Reference:
    """The cloud (set A) and, optionally, the truth, prepared for many maps (module
    docstring). ``truth`` and ``options`` as :func:`~alte.metrics.maps.measure_map` takes
    them; :meth:`fresh` gives one sharing the prepared parts with no per-leaf memory."""

    def __init__(self, cloud: NDArray[np.float64], truth: GroundTruth | None = None,
                 options: TruthSettings | None = None) -> None:
        self.cloud = cloud
        self.truth = truth
        self.options = options or TruthSettings()
        self._shared = _Shared(cloud, truth, self.options)  # shared with fresh() copies
        self._leaves: list[LeafTruth] = []

    def fresh(self) -> Reference:
        """The same prepared cloud and truth, with no per-leaf truth kept yet (a sweep
        starts one per feed, so no map's leaves outlive its runs)."""
        other = Reference(self.cloud, self.truth, self.options)
        other._shared = self._shared
        return other

    def matches(self, cloud: NDArray[np.float64], truth: GroundTruth | None,
                options: TruthSettings | None) -> bool:
        """True when made from this ``cloud``, ``truth`` and ``options``."""
        same_cloud = cloud is self.cloud or (np.shape(cloud) == np.shape(self.cloud)
                                             and np.array_equal(cloud, self.cloud))
        return (same_cloud and truth is self.truth
                and (truth is None or (options or type(self.options)()) == self.options))

    # -- set A ------------------------------------------------------------------------
    @property
    def set_a(self) -> NDArray[np.float64]:
        """The cloud as HD/MHD's set A (validated once)."""
        return self._shared.set_a

    @property
    def cloud_index(self) -> NearestIndex:
        """The cloud's nearest-neighbour grids."""
        return self._shared.cloud_index

    def hausdorff(self, b: object) -> HausdorffResult:
        """:func:`~alte.metrics.hausdorff.hausdorff` of the cloud and ``b``."""
        set_b = _as_set(b, "B")
        return summarise(NearestIndex(set_b).distances(self.set_a),
                         self.cloud_index.distances(set_b))

    # -- truth --------------------------------------------------------------------------
    def _truth(self) -> GroundTruth:
        return self._shared.ground_truth()

    @property
    def box(self) -> NDArray[np.float64]:
        """The control volume (2, 3): where samples and probes are taken."""
        return self._shared.box

    @property
    def samples(self) -> SurfaceSamples:
        """The surface samples of the 3D metrics."""
        return self._shared.samples

    @property
    def seen(self) -> NDArray[np.bool_]:
        """Samples with a registered point within the tolerance."""
        return self._shared.seen

    @property
    def sample_tree(self) -> cKDTree:
        """KD-tree over the samples (the candidate search of box distances)."""
        return self._shared.sample_tree

    @property
    def probes(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """The 2D metrics' x/y probe grid and the true top height under each probe."""
        return self._shared.probes

    def leaf_truth(self, cells: Cells) -> LeafTruth:
        """The per-leaf truth of ``cells``' geometry (kept for the next map with it)."""
        for i, known in enumerate(self._leaves):
            if known.matches(cells.centers, cells.sizes):
                self._leaves.insert(0, self._leaves.pop(i))
                return known
        made = LeafTruth(cells.centers, cells.sizes)
        self._leaves.insert(0, made)
        total = 0
        for i, known in enumerate(self._leaves):
            total += len(known)
            if total > LEAF_BUDGET and i > 0:
                del self._leaves[i:]
                break
        return made

    def truth_metrics(self, cells: Cells, dims: int) -> TruthValues:
        """What :func:`~alte.metrics.truth.ground_truth_metrics` returns for ``cells``."""
        from alte.metrics.truth import check_truth_args

        opts = self.options
        check_truth_args(dims, opts.tolerance)
        leaves = self.leaf_truth(cells)
        surface = self._truth().surface
        finite = rows_all(np.isfinite(cells.centers))
        occ = finite if dims == 2 else finite & cells.occupied.astype(bool)
        out = leaves.accuracy(occ, surface, opts.tolerance)
        if dims == 2:
            out.update(leaves.memo("heights", lambda: self._heights(cells)))
            return out
        return out | leaves.memo(("3d", occ.tobytes()), lambda: self._volume(
            leaves, cells, occ, surface))

    def _heights(self, cells: Cells) -> TruthValues:
        """:func:`~alte.metrics.truth.height_metrics_2d` on the prepared probes."""
        from alte.metrics.truth import height_summary, probe_sigma

        xy, true_h = self.probes
        known = np.isfinite(cells.centers[:, 2])
        idx = cell_at_xy(xy, cells.centers[known], cells.sizes[known])
        map_h = np.where(idx >= 0, cells.centers[known][np.maximum(idx, 0), 2], np.nan)
        return height_summary(idx, map_h, true_h, self.options.tolerance,
                              probe_sigma(cells, known, idx))

    def _volume(self, leaves: LeafTruth, cells: Cells, occ: NDArray[np.bool_],
                surface: TrueSurface) -> TruthValues:
        """The 3D metrics beyond accuracy: completeness (all, seen, per object and
        class) and the free-space truth."""
        from alte.metrics.freespace import free_space_share

        samples, seen, opts = self.samples, self.seen, self.options
        covered = leaves.covered(occ, samples.points, self.sample_tree, opts.tolerance)
        out: TruthValues = {
            "completeness": float(covered.mean()) if len(samples) else np.nan,
            "completeness_seen": float(covered[seen].mean()) if seen.any() else np.nan,
            "seen_share": float(seen.mean()) if len(samples) else np.nan,
            "completeness_by_object": completeness_by_object(samples, covered,
                                                             surface.labels)}
        if surface.classes:
            out["completeness_by_class"] = completeness_by_class(samples, covered,
                                                                 surface.classes)
        out["free_truly_free_share"] = free_space_share(
            cells, functools.partial(leaves.inside, surface=surface), seed=opts.seed)
        return out
