"""The mapper contract, version 1: what a terrain map offers to enter every part of alte.

A class that meets it is a mapper like the thesis' four: ``alte map --mapper NAME``
(``--set`` validated by its record), sweeps and the report's trade-off grid, the
answer, the obstacle and landing studies, the bench, ``.npz`` and MCAP export. The
registry (:mod:`alte.mappers.registry`) finds it by entry point; ``alte info --mappers``
lists it; :func:`alte.testing.check_mapper` checks a class against all of it.

**The class** (:class:`Mapper` is the typed protocol):

* ``api_version = API_VERSION`` (1); ``name`` (lowercase identifier, the ``--mapper``
  value and the entry point's name); ``title`` (shown in tables and figures);
* ``Settings``: a frozen :class:`~alte.params.Record` dataclass whose fields are declared
  with :func:`~alte.params.param` (default, check, rule, help); every field has a valid
  default;
* capabilities: ``dims`` (2: a height map, the cell height in ``centers[:, 2]`` and 0 in
  ``sizes[:, 2]``; 3: a volumetric map), ``incremental``, ``domain_use``
  (:class:`DomainUse`), ``default_feed`` (:class:`Feed`), ``exports`` (suffixes, ``.npz``
  always), ``free_space``, ``view_params`` (parameters that only change how the stored
  map is read), ``cost_unit`` (:class:`Cost`), ``layers`` (per-cell layers of
  :meth:`Mapper.cells`: :data:`VARIANCE`, a 2D cell's height variance in m^2, is read by
  the landing study, the metrics' sigma calibration and the MCAP export) and
  ``settings_grid`` (parameter -> values a trade-off grid crosses when its spec does not
  list the mapper);
* constructed as ``cls(domain=None, *, record=None, **params)``.

**An instance**: ``insert(points (N, 3), origin (3,))`` adds one registered scan seen
from the sensor at ``origin``; ``build(points, origins=None)`` replaces the map by one
made from a whole cloud; ``cells()`` returns :class:`Cells`; ``cell_counts()``,
``basis_functions``, ``memory_bytes``, ``corners()`` (the occupied cells' corners,
set B of the HD/MHD), ``cost`` (work in ``cost_unit``), ``points_outside``, ``params``
(an instance of ``Settings``), ``domain``, ``write_native(path)`` and ``reread(**view)``.
Bad input raises an :class:`~alte.errors.AlteError` subclass (:func:`check_points`
gives one).

:class:`MapperBase` implements everything but the map itself: a subclass sets the
names, ``dims`` and ``Settings`` and writes ``clear()``, ``_insert(points, origins)`` and
``cells()``. A class may instead implement the protocol directly (the four built-ins do).
"""

from __future__ import annotations

import copy
from collections.abc import Mapping
from pathlib import Path
from typing import ClassVar, Generic, TypeVar, cast

import numpy as np
from numpy.typing import NDArray

from alte.errors import ContractError, MapperError, ParameterError
from alte.mappers._rows import unique_rows
from alte.mappers.base import (
    API_VERSION,
    VARIANCE,
    CellCounts,
    Cells,
    Cost,
    Feed,
    Mapper,
    adopt_v1_settings,
    check_points,
    check_view,
    parsed,
)
from alte.mappers.domain import Domain, DomainUse, check_domain
from alte.params import Record, param

__all__ = ["API_VERSION", "VARIANCE", "CellCounts", "Cells", "ContractError", "Cost", "Domain",
           "DomainUse", "Feed", "Mapper", "MapperBase", "MapperError", "ParameterError",
           "Record", "check_points", "check_view", "param"]

P = TypeVar("P", bound=Record)
_SQUARE = np.array([[-1, -1], [1, -1], [-1, 1], [1, 1]], dtype=np.float64) / 2
_CUBE = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)],
                 dtype=np.float64) / 2


class MapperBase(Generic[P]):
    """Everything of the contract but the map: a subclass sets ``name``, ``title``,
    ``dims`` and ``Settings`` and implements :meth:`clear`, :meth:`_insert` and
    :meth:`cells`; the other capabilities default to an incremental, frame-fed map
    writing ``.npz`` with no view parameters, layers or settings grid.

    Points outside a given domain are dropped and counted; ``cost`` counts the points
    inserted (one cell update each: override it for another count); ``reread`` returns a
    copy with other view parameters that shares the stored arrays, so both refuse
    further inserts until a ``build``.
    """

    api_version: ClassVar[int] = API_VERSION
    name: ClassVar[str]
    title: ClassVar[str]
    dims: ClassVar[int]
    Settings: ClassVar[type[Record]]
    incremental: ClassVar[bool] = True
    domain_use: ClassVar[DomainUse] = DomainUse.OPTIONAL
    default_feed: ClassVar[Feed] = Feed.FRAMES
    exports: ClassVar[frozenset[str]] = frozenset({".npz"})
    free_space: ClassVar[bool] = False
    view_params: ClassVar[frozenset[str]] = frozenset()
    cost_unit: ClassVar[Cost] = Cost.CELL_UPDATES
    layers: ClassVar[frozenset[str]] = frozenset()
    settings_grid: ClassVar[Mapping[str, tuple[object, ...]]] = {}

    def __init_subclass__(cls, **kwargs: object) -> None:
        super().__init_subclass__(**kwargs)
        adopt_v1_settings(cls)  # a v1 class naming its record Params keeps working

    def __init__(self, domain: Domain | None = None, *, record: Record | None = None,
                 **given: object) -> None:
        self._domain = check_domain(self.name, domain)
        self._record = cast(P, parsed(self.Settings, record, given))
        self.points_outside = 0
        self._cost = 0
        self._shared = False
        self.clear()

    # -- what a subclass writes ----------------------------------------------------------
    def clear(self) -> None:
        """Empty the map (called by the constructor and by :meth:`build`)."""
        raise NotImplementedError

    def _insert(self, points: NDArray[np.float64], origins: NDArray[np.float64] | None) -> None:
        """Add checked points (N, 3) inside the domain, each seen from ``origins`` (N, 3)
        (None: a cloud given to ``build`` without origins)."""
        raise NotImplementedError

    def cells(self) -> Cells:
        """The map's cells as arrays."""
        raise NotImplementedError

    # -- the rest of the contract --------------------------------------------------------
    @property
    def params(self) -> P:
        """The validated parameters, defaults filled in."""
        return self._record

    @property
    def domain(self) -> Domain | None:
        """The domain given (None: the map's own extent)."""
        return self._domain

    @property
    def cost(self) -> int:
        """Points inserted since creation or the last build."""
        return self._cost

    def insert(self, points: NDArray[np.float64], origin: NDArray[np.float64]) -> None:
        """Add one registered frame (N, 3) seen from ``origin`` (3,)."""
        if self._shared:
            raise MapperError(f"{self.name}: this map shares its cells with a re-read copy; "
                              "build it afresh to add points")
        pts = check_points(points, self.name)
        where = np.asarray(origin, dtype=np.float64)
        if where.shape != (3,) or not np.isfinite(where).all():
            raise MapperError(f"{self.name}: origin must be 3 finite numbers, got "
                              f"{where.tolist()}")
        self._add(pts, np.broadcast_to(where, pts.shape))

    def build(self, points: NDArray[np.float64],
              origins: NDArray[np.float64] | None = None) -> None:
        """Replace the map by one built from a whole cloud (origins: (3,) or (N, 3))."""
        pts = check_points(points, self.name)
        seen = None
        if origins is not None:
            seen = np.asarray(origins, dtype=np.float64)
            if seen.shape == (3,):
                seen = np.broadcast_to(seen, pts.shape)
            if seen.shape != pts.shape or not np.isfinite(seen).all():
                raise MapperError(f"{self.name}: origins must be (3,) or one finite row per "
                                  f"point {pts.shape}, got {seen.shape}")
        self.clear()
        self.points_outside, self._cost, self._shared = 0, 0, False
        self._add(pts, seen)

    def _add(self, points: NDArray[np.float64], origins: NDArray[np.float64] | None) -> None:
        if self._domain is not None and len(points):
            inside = self._domain.inside(points, self.dims)
            self.points_outside += int(np.count_nonzero(~inside))
            points = points[inside]
            origins = None if origins is None else origins[inside]
        self._insert(points, origins)
        self._cost += len(points)

    def cell_counts(self) -> CellCounts:
        """``len(cells())`` and its occupied count."""
        return CellCounts.of(self.cells())

    @property
    def basis_functions(self) -> int:
        """The number of cells."""
        return len(self.cells())

    @property
    def memory_bytes(self) -> int:
        """Bytes of the numpy arrays the instance holds."""
        return int(sum(v.nbytes for v in vars(self).values() if isinstance(v, np.ndarray)))

    def corners(self) -> NDArray[np.float64]:
        """Distinct corners of the occupied cells with a known height (2D: the four
        corners at the cell's height; 3D: the eight corners of the box)."""
        cells = self.cells()
        keep = cells.occupied & np.isfinite(cells.centers).all(axis=1)
        centers, sizes = cells.centers[keep], cells.sizes[keep]
        if self.dims == 2:
            xy = centers[:, None, :2] + _SQUARE[None] * sizes[:, None, :2]
            z = np.broadcast_to(centers[:, None, 2:], (*xy.shape[:2], 1))
            pts = np.concatenate([xy, z], axis=2)
        else:
            pts = centers[:, None, :] + _CUBE[None] * sizes[:, None, :]
        return unique_rows(pts.reshape(-1, 3))

    def write_native(self, path: Path, overwrite: bool = False) -> Path:
        """No native format: the cells go to ``.npz``."""
        raise MapperError(f"{self.name}: writes {', '.join(sorted(self.exports))} only, "
                          f"not {Path(path).suffix or 'no suffix'}")

    def reread(self, **changes: object) -> MapperBase[P]:
        """A copy read with other ``view_params`` values (the stored arrays shared)."""
        check_view(cast(Mapper, self), changes)
        if not changes:
            return self
        other = copy.copy(self)
        other._record = self._record.replace(**changes)
        self._shared = other._shared = True
        return other
