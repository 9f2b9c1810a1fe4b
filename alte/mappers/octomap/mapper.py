"""Octomap (thesis 3.2): probabilistic occupancy octree with free-space ray casting.

Two interchangeable backends: ``native`` (default; numba ray casting that reproduces
OctoMap 1.10's ``insertPointCloud`` key for key, see ``_raycast``) and ``reference``
(the C++ OctoMap library through ``pyoctomap``). The default sensor model is MATLAB's
``occupancyMap3D``, which the thesis used; ``sensor_model=octomap`` selects OctoMap's
own defaults. Any single value can still be overridden (``prob_hit=0.8``).

The domain is OctoMap's fixed key space (2^16 voxels per axis centred on 0), so
frames can be inserted one at a time with no ``domain`` parameter.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import ClassVar, Literal, Protocol

import numpy as np
from numpy.typing import NDArray

from alte.errors import MapperError, ParameterError
from alte.fsutil import atomic_path
from alte.mappers._rows import unique_rows
from alte.mappers.base import (
    API_VERSION,
    CellCounts,
    Cells,
    Cost,
    Feed,
    check_points,
    check_view,
    parsed,
    renamed,
)
from alte.mappers.domain import Domain, DomainUse
from alte.mappers.octomap.backends import NativeTree, ReferenceTree, SensorModel
from alte.mappers.octomap.cells import leaf_subset, leaves_to_cells, occupied_voxels
from alte.mappers.octree.raycast import TREE_MAX_VAL
from alte.mappers.octree.tree import Leaves, check_origin, leaf_geometry
from alte.params import Record, param
from alte.types import rows_all

__all__ = ["SENSOR_MODELS", "Octomap", "OctomapSettings"]

#: Sensor models: MATLAB occupancyMap3D (its free threshold 0.2 only affects MATLAB's
#: ``checkOccupancy`` queries, not the map) and OctoMap's library defaults.
SENSOR_MODELS: dict[str, dict[str, float]] = {
    "matlab": {"prob_hit": 0.7, "prob_miss": 0.4, "clamp_min": 0.001, "clamp_max": 0.999,
               "occupancy_threshold": 0.65},
    "octomap": {"prob_hit": 0.7, "prob_miss": 0.4, "clamp_min": 0.1192, "clamp_max": 0.971,
                "occupancy_threshold": 0.5},
}


class _Backend(Protocol):
    """What the mapper asks of a backend (:mod:`alte.mappers.octomap.backends`)."""

    model: SensorModel

    def insert_scan(self, points: NDArray[np.float64], origin: NDArray[np.float64]) -> None: ...
    def insert_hits(self, points: NDArray[np.float64]) -> None: ...
    def leaves(self) -> Leaves[np.float32]: ...
    def write_bt(self, path: Path) -> None: ...
    @property
    def num_leaves(self) -> int: ...
    @property
    def memory_bytes(self) -> int: ...
    @property
    def cost(self) -> int: ...


#: Backend by name, built from (voxel size, max range, sensor model).
_BACKENDS: dict[str, Callable[[float, float, SensorModel], _Backend]] = {
    "native": NativeTree, "reference": ReferenceTree}


def _prob(low: float, high: float) -> Callable[[float], bool]:
    return lambda v: low < v < high


@dataclass(frozen=True)
class OctomapSettings(Record):
    """Octomap parameters; unset probabilities come from ``sensor_model``."""

    OWNER: ClassVar[str] = "octomap"
    resolution: float = param(5.0, lambda v: v > 0, "> 0", "cells per metre")
    backend: Literal["native", "reference"] = param(
        "native", help="our numba tree or the C++ OctoMap library")
    sensor_model: Literal["matlab", "octomap"] = param("matlab",
                                                       help="defaults of the four probabilities")
    max_range: float = param(100.0, lambda v: v > 0 or v == -1, "> 0, or -1 = unlimited",
                             "longer rays are truncated and their end not marked occupied")
    prob_hit: float | None = param(None, _prob(0.5, 1), "0.5 < p < 1")
    prob_miss: float | None = param(None, _prob(0, 0.5), "0 < p < 0.5")
    clamp_min: float | None = param(None, _prob(0, 0.5), "0 < p < 0.5")
    clamp_max: float | None = param(None, _prob(0.5, 1), "0.5 < p < 1")
    occupancy_threshold: float | None = param(None, _prob(0, 1), "0 < p < 1")

    def __post_init__(self) -> None:
        super().__post_init__()
        for name, value in SENSOR_MODELS[self.sensor_model].items():
            if getattr(self, name) is None:
                object.__setattr__(self, name, value)
        model = self.model()
        if model.clamp_min >= model.occupancy_threshold:
            raise ParameterError("octomap: clamp_min must be below occupancy_threshold")
        if model.clamp_max <= model.occupancy_threshold:
            raise ParameterError("octomap: clamp_max must be above occupancy_threshold")

    def model(self) -> SensorModel:
        """The five probabilities (sensor-model defaults filled in) as a :class:`SensorModel`."""
        hit, miss = self.prob_hit, self.prob_miss
        low, high, threshold = self.clamp_min, self.clamp_max, self.occupancy_threshold
        assert hit is not None and miss is not None, "filled by __post_init__"
        assert low is not None and high is not None and threshold is not None, "filled too"
        return SensorModel(hit, miss, low, high, threshold)


class Octomap:
    """Occupancy octree, incremental by construction (each ``insert`` is one scan).

    ``cells()`` are the leaves after pruning identical siblings (value = occupancy
    probability, occupied = p > ``occupancy_threshold``, level = depth, size =
    voxel * 2^(16 - depth)). ``basis_functions`` counts ALL leaves, free and
    occupied, as OctoMap's ``getNumLeafNodes`` does (a planner must handle the
    known free space too; thesis table 5.8). ``build(points, origins)`` with one
    origin per point inserts each run of equal origins as one scan, so it equals
    inserting those frames; one origin for the whole cloud is ONE scan (each voxel
    updated once), which differs from several inserts. ``origins=None`` marks the
    point voxels occupied once with no ray casting (no free space).
    """

    api_version: ClassVar[int] = API_VERSION
    name: ClassVar[str] = "octomap"
    title: ClassVar[str] = "Octomap"
    dims: ClassVar[int] = 3
    incremental: ClassVar[bool] = True
    domain_use: ClassVar[DomainUse] = DomainUse.UNUSED
    default_feed: ClassVar[Feed] = Feed.FRAMES
    exports: ClassVar[frozenset[str]] = frozenset({".npz", ".bt"})
    free_space: ClassVar[bool] = True
    #: Every parameter changes the log-odds the tree stores.
    view_params: ClassVar[frozenset[str]] = frozenset()
    cost_unit: ClassVar[Cost] = Cost.RAY_STEPS
    layers: ClassVar[frozenset[str]] = frozenset()
    settings_grid: ClassVar[Mapping[str, tuple[object, ...]]] = {
        "resolution": (0.5, 0.75, 1.0, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0)}
    Settings: ClassVar[type[Record]] = OctomapSettings
    #: Contract v1's first name of :attr:`Settings` (deprecated; still read by old code).
    Params: ClassVar[type[Record]] = OctomapSettings

    def __init__(self, domain: Domain | None = None, *, record: Record | None = None,
                 **given: object) -> None:
        if domain is not None:
            raise MapperError("octomap: its domain is the fixed key space of 2^16 voxels per "
                              "axis around 0; it takes no domain")
        self._record = parsed(OctomapSettings, record, given)
        self._tree = self._new_tree()
        self.points_outside = 0
        self._cells: tuple[Leaves[np.float32], Cells] | None = None  # the cells of those leaves

    def reread(self, **changes: object) -> Octomap:
        """Octomap has no view parameters: the map itself (any change raises)."""
        check_view(self, changes)
        return self

    def _new_tree(self) -> _Backend:
        rec = self._record
        return _BACKENDS[rec.backend](1.0 / rec.resolution, rec.max_range, rec.model())

    @property
    def params(self) -> Record:
        """The validated parameters, sensor-model defaults filled in."""
        return self._record

    @property
    def domain(self) -> Domain | None:
        """None: Octomap's key space is fixed (2^16 voxels per axis centred on 0)."""
        return None

    def _count_outside(self, pts: NDArray[np.float64]) -> NDArray[np.bool_]:
        """Points inside the key space; the others are counted (their rays are skipped)."""
        half = TREE_MAX_VAL * self.voxel_size
        inside = rows_all((pts >= -half) & (pts < half))
        self.points_outside += int(inside.size - np.count_nonzero(inside))
        return inside

    @property
    def voxel_size(self) -> float:
        """Edge of a finest voxel in metres (1 / resolution)."""
        return 1.0 / self._record.resolution

    def insert(self, points: NDArray[np.float64], origin: NDArray[np.float64]) -> None:
        """Integrate one scan: free space along every ray, occupied end voxels."""
        pts = check_points(points, "octomap")
        start = check_origin(origin, "octomap")
        self._count_outside(pts)
        self._tree.insert_scan(pts, start)

    def build(self, points: NDArray[np.float64],
              origins: NDArray[np.float64] | None = None) -> None:
        """Rebuild from a cloud; see the class docstring for the meaning of ``origins``."""
        pts = check_points(points, "octomap")
        self._tree = self._new_tree()
        self.points_outside = 0
        self._count_outside(pts)
        if origins is None:
            self._tree.insert_hits(pts)
            return
        orig = np.asarray(origins, dtype=np.float64)
        if orig.shape == (3,):
            orig = np.broadcast_to(orig, pts.shape)
        orig = check_points(orig, "octomap", "origins")
        if orig.shape != pts.shape:
            raise MapperError(
                f"octomap: origins must be (3,) or one per point {pts.shape}, got {orig.shape}"
            )
        cuts = np.flatnonzero((orig[1:] != orig[:-1]).any(axis=1)) + 1
        for part, start in zip(np.split(pts, cuts), np.r_[0, cuts], strict=True):
            if part.size:
                self._tree.insert_scan(part, orig[start])

    def leaves(self) -> Leaves[np.float32]:
        """Pruned leaves as Morton prefixes, depths and float32 log-odds."""
        return self._tree.leaves()

    def cells(self) -> Cells:
        """The leaves as cells (kept while the leaves are: a flight at 0.1 m has tens of
        millions, seconds to convert)."""
        leaves = self.leaves()
        if self._cells is None or self._cells[0] is not leaves:
            self._cells = (leaves, leaves_to_cells(leaves, self.voxel_size,
                                                   self._tree.model.occupied))
        return self._cells[1]

    def cell_counts(self) -> CellCounts:
        """Leaves and occupied leaves, from the leaf values alone (no centres or sizes)."""
        value = self.leaves().value
        return CellCounts(len(value), int(np.count_nonzero(value > self._tree.model.occupied)))

    @property
    def basis_functions(self) -> int:
        return self._tree.num_leaves

    @property
    def cost(self) -> int:
        """Ray steps: voxels crossed by every ray plus its end voxel (:class:`Cost`)."""
        return self._tree.cost

    @property
    def memory_bytes(self) -> int:
        """Native: bytes of the key and log-odds arrays; reference: OctoMap's memoryUsage."""
        return self._tree.memory_bytes

    def occupied_voxels(self) -> NDArray[np.uint64]:
        """Sorted Morton keys of the occupied depth-16 voxels (pruned leaves expanded)."""
        return occupied_voxels(self.leaves(), self._tree.model.occupied)

    def corners(self) -> NDArray[np.float64]:
        """The 8 corners of every occupied leaf, de-duplicated on the voxel grid."""
        leaves = self.leaves()
        occ = leaves.value > self._tree.model.occupied
        min_keys, side, _ = leaf_geometry(leaf_subset(leaves, occ), self.voxel_size)
        offsets = np.array([[i >> 2 & 1, i >> 1 & 1, i & 1] for i in range(8)])
        grid = (min_keys[:, None, :] + offsets[None] * side[:, None, None]).reshape(-1, 3)
        return (unique_rows(grid) - TREE_MAX_VAL) * self.voxel_size

    def write_native(self, path: Path, overwrite: bool = False) -> Path:
        """The OctoMap binary tree (``.bt``), see :meth:`write_bt`."""
        return self.write_bt(path, overwrite)

    def write_bt(self, path: str | Path, overwrite: bool = False) -> Path:
        """Write an OctoMap maximum-likelihood binary tree (``.bt``)."""
        target = Path(path)
        with atomic_path(target, overwrite=overwrite) as tmp:
            self._tree.write_bt(tmp)
        return target


def __getattr__(name: str) -> object:
    """``OctomapParams``: the first name of :class:`OctomapSettings` (deprecated)."""
    return renamed(__name__, name, {"OctomapParams": lambda: OctomapSettings})
