"""All metrics of one map as one typed record: the thesis' (5.2.1) and the ground-truth ones.

:func:`measure_map` takes the map, the registered cloud (set A) and, for simulated
terrains, the true surface; it returns a :class:`MapMetrics`. ``flat()`` gives the
scalar columns of a table row (per-class completeness as ``completeness_<class>``;
per-object values stay in :attr:`TruthMetrics.completeness_by_object`).
"""

from __future__ import annotations

import dataclasses
import enum
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from alte.errors import MetricsError
from alte.mappers.quad.quadmap import rectangle_corners
from alte.metrics.hausdorff import hausdorff
from alte.metrics.options import GroundTruth, TruthSettings
from alte.metrics.timing import Timing
from alte.types import rows_all

if TYPE_CHECKING:
    from alte.mappers.base import Cells, Mapper
    from alte.metrics.reference import Reference

__all__ = [
    "SET_B",
    "GroundTruth",
    "MapMetrics",
    "MapPointSet",
    "TruthMetrics",
    "TruthSettings",
    "measure_map",
    "set_b_points",
    "set_b_rule",
]

_NAN = float("nan")
#: Definitions of set B (the map's points in HD/MHD): ``corners`` of every basis function
#: (thesis 5.2.1, fig. 5.1) or their ``centers``, either way of the occupied cells (3D) or
#: of every cell with a height (2D: a height map's free cells are ground); ``occupied``:
#: corners of the cells the mapper marks occupied (2D: Quadtree's height-above-ground
#: rule; every known cell of 2D-ALTE; 3D: the same as ``corners``).
class MapPointSet(enum.StrEnum):
    """Which points of a map are set B of its HD/MHD (comment above)."""

    CORNERS = "corners"
    CENTERS = "centers"
    OCCUPIED = "occupied"


#: The names of :class:`MapPointSet` (what a sweep spec or a notebook may give).
SET_B = tuple(s.value for s in MapPointSet)


def set_b_rule(value: MapPointSet | str) -> MapPointSet:
    """``value`` as a :class:`MapPointSet`, or :class:`MetricsError` naming the valid ones."""
    try:
        return MapPointSet(value)
    except ValueError as err:
        raise MetricsError(f"set B {value!r}: expected one of {', '.join(SET_B)}") from err


@dataclass(frozen=True)
class TruthMetrics:
    """Ground-truth metrics (NaN where a metric does not apply to the map's kind)."""

    accuracy_mean_m: float = _NAN
    accuracy_p95_m: float = _NAN
    phantom_share: float = _NAN
    completeness: float = _NAN
    completeness_seen: float = _NAN
    seen_share: float = _NAN
    height_rmse_m: float = _NAN
    unknown_share: float = _NAN
    within_2sigma: float = _NAN
    sigma_mean_m: float = _NAN
    free_truly_free_share: float = _NAN
    completeness_by_class: Mapping[str, float] = field(default_factory=dict)
    completeness_by_object: Mapping[str, float] = field(default_factory=dict)


@dataclass(frozen=True)
class MapMetrics:
    """One map's time (:class:`~alte.metrics.timing.Timing`: the least ``elapsed_s``
    and ``map_cpu_s`` over ``time_repeats`` runs, with their spreads) and its
    machine-independent ``cost`` (in its mapper's ``cost_unit``), size, thesis fidelity
    metrics (set A = cloud, set B = corners) and truth."""

    elapsed_s: float
    elapsed_spread: float
    map_cpu_s: float
    map_cpu_spread: float
    time_repeats: int
    cost: int
    basis_functions: int
    memory_bytes: int
    occupied_cells: int
    cell_min_m: float
    cell_max_m: float
    size_octaves: float
    hd_m: float
    mhd_m: float
    hd_minus_mhd_m: float
    h_ab_m: float
    h_ba_m: float
    mh_ab_m: float
    mh_ba_m: float
    truth: TruthMetrics | None = None

    def flat(self) -> dict[str, float]:
        """Scalar metrics for a table row (see the module docstring)."""
        out: dict[str, float] = {f.name: getattr(self, f.name)
                                 for f in dataclasses.fields(self) if f.name != "truth"}
        if self.truth is not None:
            for f in dataclasses.fields(self.truth):
                value = getattr(self.truth, f.name)
                if not isinstance(value, Mapping):
                    out[f.name] = value
            for cls, value in self.truth.completeness_by_class.items():
                out[f"completeness_{cls}"] = value
        return out

    def as_dict(self) -> dict[str, object]:
        """Everything, nested (per-object completeness included), JSON-ready."""
        return dataclasses.asdict(self)


def _size_spread(cells: Cells) -> tuple[float, float, float]:
    """Cell edge range of the known cells: the "adaptability" of tables 5.1-5.2."""
    finite = np.isfinite(cells.centers)
    edge = cells.sizes[:, 0] if finite.all() else cells.sizes[finite.all(axis=1), 0]
    if edge.size == 0:
        return _NAN, _NAN, _NAN
    lo, hi = float(edge.min()), float(edge.max())
    return lo, hi, float(np.log2(hi / lo))


def set_b_points(mapper: Mapper, cells: Cells, rule: MapPointSet = MapPointSet.CORNERS,
                 ) -> NDArray[np.float64]:
    """Set B of the thesis' HD/MHD by ``rule`` (see :class:`MapPointSet`), (M, 3)."""
    rule = set_b_rule(rule)
    if rule is MapPointSet.CORNERS or (rule is MapPointSet.OCCUPIED and mapper.dims == 3):
        return mapper.corners()
    keep = rows_all(np.isfinite(cells.centers))
    if mapper.dims == 3 or rule is MapPointSet.OCCUPIED:
        keep &= cells.occupied.astype(bool)
    if rule is MapPointSet.OCCUPIED:
        return rectangle_corners(cells, keep)
    return np.asarray(cells.centers[keep], dtype=np.float64)


def _thesis(points: NDArray[np.float64], cloud: NDArray[np.float64],
            reference: Reference | None = None) -> dict[str, float]:
    """HD/MHD between the cloud and set B; NaN when set B is empty (nothing occupied)."""
    names = ("hd_m", "mhd_m", "hd_minus_mhd_m", "h_ab_m", "h_ba_m", "mh_ab_m", "mh_ba_m")
    if len(points) == 0 or len(cloud) == 0:  # undefined, not zero
        return dict.fromkeys(names, _NAN)
    hd = hausdorff(cloud, points) if reference is None else reference.hausdorff(points)
    return dict(zip(names, (hd.hd, hd.mhd, hd.hd - hd.mhd, hd.h_ab, hd.h_ba, hd.mh_ab,
                            hd.mh_ba), strict=True))


def measure_map(mapper: Mapper, cloud: NDArray[np.float64], *, elapsed_s: float | Timing,
                truth: GroundTruth | None = None, options: TruthSettings | None = None,
                set_b: MapPointSet = MapPointSet.CORNERS, reference: Reference | None = None,
                cells: Cells | None = None) -> MapMetrics:
    """Every metric of ``mapper`` against the registered ``cloud`` (and ``truth``);
    ``elapsed_s``: the mapping's time (one wall reading, or a :class:`Timing`);
    ``set_b`` defines the map's points of HD/MHD (:class:`MapPointSet`). ``reference``: the
    same ``cloud``, ``truth`` and ``options`` prepared once for many maps
    (:class:`~alte.metrics.reference.Reference`): the same values, with the work the
    maps of one input share done once. ``cells``: the map's cells when the caller has
    listed them already (a large Octomap's leaves take seconds to list)."""
    timing = elapsed_s if isinstance(elapsed_s, Timing) else Timing(float(elapsed_s))
    set_b = set_b_rule(set_b)
    if reference is not None and not reference.matches(cloud, truth, options):
        raise MetricsError("measure_map: the reference was prepared from another cloud, "
                           "truth or truth options")
    cells = mapper.cells() if cells is None else cells  # listed once
    lo, hi, octaves = _size_spread(cells)
    truth_metrics = None
    if truth is not None and reference is not None:
        truth_metrics = TruthMetrics(**reference.truth_metrics(cells, mapper.dims))
    elif truth is not None:
        from alte.metrics.truth import ground_truth_metrics

        opts = options or TruthSettings()
        truth_metrics = TruthMetrics(**ground_truth_metrics(
            cells, truth.surface, dims=mapper.dims, cloud=cloud, bounds=truth.bounds.array(),
            tolerance=opts.tolerance, n_samples=opts.n_samples, grid_step=opts.grid_step,
            seed=opts.seed))
    return MapMetrics(
        elapsed_s=timing.elapsed_s, elapsed_spread=timing.elapsed_spread,
        map_cpu_s=timing.cpu_s, map_cpu_spread=timing.cpu_spread,
        time_repeats=timing.repeats, cost=int(mapper.cost),
        basis_functions=int(mapper.basis_functions),
        memory_bytes=int(mapper.memory_bytes),
        occupied_cells=int(np.count_nonzero(cells.occupied)), cell_min_m=lo, cell_max_m=hi,
        size_octaves=octaves,
        **_thesis(set_b_points(mapper, cells, set_b), cloud, reference),
        truth=truth_metrics)
