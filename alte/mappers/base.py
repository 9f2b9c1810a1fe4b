"""The ``Mapper`` protocol, the cell arrays every map exposes, and parameter parsing.

A mapper turns registered (inertial) points into a map. It is fed either one frame
at a time with :meth:`Mapper.insert` (points plus the sensor origin, as the thesis'
real-time loop does) or a whole cloud at once with :meth:`Mapper.build`.
"""

from __future__ import annotations

import enum
import warnings
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import ClassVar, Protocol, TypeVar, runtime_checkable

import numpy as np
from numpy.typing import NDArray

from alte.errors import MapperError
from alte.mappers.domain import Domain, DomainUse
from alte.params import Record
from alte.types import as_points

__all__ = [
    "API_VERSION",
    "VARIANCE",
    "CellCounts",
    "Cells",
    "Cost",
    "Feed",
    "Mapper",
    "adopt_v1_settings",
    "check_points",
    "check_view",
    "parsed",
    "renamed",
]

#: The version of the mapper contract (:mod:`alte.mappers.api`); a mapper declares the one
#: it was written against as ``api_version`` and the registry refuses another.
API_VERSION = 1
#: The layer of a 2D map's cells holding each cell's height variance (m^2).
VARIANCE = "variance"


@dataclass(frozen=True)
class Cells:
    """A map's cells as parallel arrays (one row per leaf / basis function).

    ``centers`` (K, 3) and ``sizes`` (K, 3) in metres: 2D maps put the cell height
    in ``centers[:, 2]`` and 0 in ``sizes[:, 2]``. ``value`` is the mapper's own
    quantity (mean height, occupancy probability, point count), ``occupied`` the
    binary state and ``level`` the tree depth (0 = root). ``layers`` holds further
    per-cell quantities by name, one float64 value per cell (the mapper's class lists
    them in ``Mapper.layers``): :data:`VARIANCE` is a 2D cell's height variance (m^2).
    """

    centers: NDArray[np.float64]
    sizes: NDArray[np.float64]
    value: NDArray[np.float64]
    occupied: NDArray[np.bool_]
    level: NDArray[np.int64]
    layers: Mapping[str, NDArray[np.float64]] = field(default_factory=dict)

    def __len__(self) -> int:
        return int(self.centers.shape[0])

    def layer(self, name: str) -> NDArray[np.float64] | None:
        """The per-cell layer ``name`` (None when the map has none)."""
        return self.layers.get(name)

    def subset(self, mask: NDArray[np.bool_]) -> Cells:
        """The cells where ``mask`` holds, layers included."""
        return Cells(self.centers[mask], self.sizes[mask], self.value[mask],
                     self.occupied[mask], self.level[mask],
                     {name: values[mask] for name, values in self.layers.items()})

    def as_dict(self) -> dict[str, NDArray[np.float64] | NDArray[np.bool_] | NDArray[np.int64]]:
        """Arrays by name, as written by ``alte map --export cells.npz`` (a layer ``L`` as
        ``layer_L``)."""
        return {
            "centers": self.centers,
            "sizes": self.sizes,
            "value": self.value,
            "occupied": self.occupied,
            "level": self.level,
            **{f"layer_{name}": values for name, values in self.layers.items()},
        }


@dataclass(frozen=True)
class CellCounts:
    """How many cells a map has and how many of them are occupied."""

    cells: int
    occupied: int

    @classmethod
    def of(cls, cells: Cells) -> CellCounts:
        """The counts of a materialised :class:`Cells` table."""
        return cls(len(cells), int(np.count_nonzero(cells.occupied)))


class Cost(enum.Enum):
    """What a mapper's :attr:`Mapper.cost` counts: the work of its mapping, independent of
    the machine (and of other load on it), to be read beside the measured time.

    ``CELL_UPDATES``: points located in the tree plus, on every level, the cells whose
    statistics an insertion or build wrote (the tree maps: Quadtree, 2D-ALTE, 3D-ALTE).
    ``RAY_STEPS``: voxels the scan's rays step through (free-space ray casting) plus the
    end voxel of every ray (Octomap). Counts of different units are not comparable.
    """

    CELL_UPDATES = "cell updates"
    RAY_STEPS = "ray steps"


class Feed(enum.Enum):
    """How a map is fed: one registered frame at a time, or the merged cloud once."""

    FRAMES = "frames"
    BATCH = "batch"


@runtime_checkable
class Mapper(Protocol):
    """What every mapper offers (the contract of :mod:`alte.mappers.api`, version
    :data:`API_VERSION`); mappers are found through :mod:`alte.mappers.registry`.

    A mapper class is constructed as ``cls(domain=None, *, record=None, **params)``: a
    :class:`~alte.mappers.domain.Domain` or None, and its parameters either as an
    instance of its ``Settings`` record or as names and values that record parses.

    Capabilities are class attributes the pipeline reads (never probed with hasattr):
    ``dims``, ``incremental``, ``domain_use``, ``default_feed`` (the thesis' protocol:
    Quadtree ran once on the final cloud), ``exports`` (file suffixes it writes),
    ``free_space`` (its unoccupied cells were observed free), ``cost_unit`` (what
    :attr:`cost` counts), ``view_params`` (the parameters :meth:`reread` can
    change), ``layers`` (the per-cell layers :meth:`cells` carries) and
    ``settings_grid`` (the settings a trade-off grid crosses when its spec does not
    list the mapper).
    """

    #: The contract version the class was written against (:data:`API_VERSION`).
    api_version: ClassVar[int]
    #: The name the registry, the CLI (``--mapper``) and the sweep specs use.
    name: ClassVar[str]
    #: The name tables, figures and the report show ("2D-ALTE").
    title: ClassVar[str]
    #: The parameter record: ``--set`` values and sweep rows are validated by it.
    Settings: ClassVar[type[Record]]
    #: 2 for height maps (Quadtree, 2D-ALTE), 3 for volumetric maps.
    dims: ClassVar[int]
    #: True when ``insert`` updates only what the new frame touches.
    incremental: ClassVar[bool]
    domain_use: ClassVar[DomainUse]
    default_feed: ClassVar[Feed]
    #: Suffixes :func:`alte.mappers.export_map` can write for this mapper.
    exports: ClassVar[frozenset[str]]
    #: True when unoccupied cells are observed free space (ray casting), not just "not hit".
    free_space: ClassVar[bool]
    #: Parameters that only decide how the stored map is read (which cells split, which
    #: are occupied), not what ``insert``/``build`` store nor the work they do: a map
    #: re-read with other values of these equals the map made with them.
    view_params: ClassVar[frozenset[str]]
    #: The unit of :attr:`cost`.
    cost_unit: ClassVar[Cost]
    #: Names of the per-cell layers of :meth:`cells` (``Cells.layers``), e.g. ``variance``.
    layers: ClassVar[frozenset[str]]
    #: Parameter values a trade-off grid crosses (their product) when its spec does not
    #: list the mapper; empty: the defaults alone. The first parameter is the one that
    #: sets the map's size (the bench samples a sweep by it).
    settings_grid: ClassVar[Mapping[str, tuple[object, ...]]]

    def __init__(self, domain: Domain | None = None, *, record: Record | None = None,
                 **given: object) -> None:
        """The map over ``domain`` (None: grown from the data or a key space of its own),
        parameters as a ``Settings`` record or as names and values it parses."""

    @property
    def params(self) -> Record:
        """The validated parameters, defaults filled in."""
        ...

    @property
    def domain(self) -> Domain | None:
        """The root cell (None: grown from the data, or a key space of its own)."""
        ...

    @property
    def points_outside(self) -> int:
        """Points given to ``insert``/``build`` that fell outside the domain and were dropped."""
        ...

    @property
    def cost(self) -> int:
        """Machine-independent work (in ``cost_unit``) of the calls that made this map:
        every ``insert`` since creation or the last ``build``, which starts it afresh."""
        ...

    def insert(self, points: NDArray[np.float64], origin: NDArray[np.float64]) -> None:
        """Add one registered frame (N, 3) seen from sensor ``origin`` (3,)."""
        ...

    def build(self, points: NDArray[np.float64],
              origins: NDArray[np.float64] | None = None) -> None:
        """Replace the map by one built from a whole cloud (origins: (3,) or (N, 3))."""
        ...

    def cells(self) -> Cells:
        """The map's leaves as arrays."""
        ...

    def cell_counts(self) -> CellCounts:
        """``len(cells())`` and its occupied count, without building the arrays where the
        map is large (an Octomap flight holds tens of millions of free leaves)."""
        ...

    @property
    def basis_functions(self) -> int:
        """Number of cells a path planner must handle (thesis 5.2.1)."""
        ...

    @property
    def memory_bytes(self) -> int:
        """Bytes held by the map's data structures."""
        ...

    def corners(self) -> NDArray[np.float64]:
        """Corners of the occupied basis functions (M, 3): set B of thesis fig. 5.1."""
        ...

    def write_native(self, path: Path, overwrite: bool = False) -> Path:
        """Write the map in its own format (the non-``.npz`` suffix of ``exports``)."""
        ...

    def reread(self, **changes: object) -> Mapper:
        """This map read with other values of ``view_params`` (a sweep's settings that
        differ in those only share one feed). The copy shares the stored map: from then
        on neither takes more points until a ``build`` starts it afresh."""
        ...


def check_points(points: object, owner: str, name: str = "points") -> NDArray[np.float64]:
    """Return finite float64 (N, 3) points or raise :class:`MapperError` naming the problem."""
    return as_points(points, name, owner=owner, error=MapperError, finite=True)


def check_view(mapper: Mapper, changes: Mapping[str, object]) -> None:
    """Raise :class:`MapperError` when ``changes`` (what :meth:`Mapper.reread` takes)
    name a parameter outside ``mapper.view_params``, naming the ones that can change;
    their values are checked by the parameter record."""
    stored = sorted(set(changes) - mapper.view_params)
    if stored:
        can = ", ".join(sorted(mapper.view_params)) or "none"
        raise MapperError(f"{mapper.name}: {', '.join(stored)} change(s) what the map stores; "
                          f"a map can be re-read with other {can} only")


_R = TypeVar("_R", bound=Record)


def parsed(params: type[_R], record: Record | None, given: Mapping[str, object]) -> _R:
    """A mapper's parameters: ``record`` when one was resolved already (a
    :class:`~alte.pipeline.MapSettings`'s), else ``given`` parsed; never both."""
    if record is None:
        return params.parse(given)
    if not isinstance(record, params):
        raise MapperError(f"{params.OWNER}: its parameters are a {params.__name__}, not a "
                          f"{type(record).__name__}")
    if given:
        raise MapperError(f"{params.OWNER}: parameters come as a record or as names and "
                          f"values, not both ({', '.join(sorted(given))} beside the record)")
    return record


def adopt_v1_settings(cls: type) -> None:
    """Contract v1 first named a mapper's settings record ``Params``; a class that still
    does gets ``Settings`` from it, with a :class:`DeprecationWarning` (it keeps working),
    and a class naming ``Settings`` keeps ``Params`` as an alias for code that reads it."""
    own = vars(cls)
    if "Settings" not in own and "Params" in own:
        warnings.warn(f"{cls.__module__}.{cls.__qualname__}: the settings record is named "
                      "Settings now; Params (mapper contract v1's first name) still works "
                      "but is deprecated", DeprecationWarning, stacklevel=3)
        cls.Settings = own["Params"]  # type: ignore[attr-defined]
    if "Settings" in vars(cls) and "Params" not in own:
        cls.Params = vars(cls)["Settings"]  # type: ignore[attr-defined]


def renamed(module: str, name: str, names: Mapping[str, Callable[[], object]]) -> object:
    """A module's ``__getattr__`` for names it renamed: the new object, with a
    :class:`DeprecationWarning` naming the new name; other names raise AttributeError."""
    if name not in names:
        raise AttributeError(f"module {module!r} has no attribute {name!r}")
    new = names[name]()
    warnings.warn(f"{module}.{name} is deprecated; use {getattr(new, '__name__', new)}",
                  DeprecationWarning, stacklevel=3)
    return new
