"""The ``Mapper`` protocol, the cell arrays every map exposes, and parameter parsing.

A mapper turns registered (inertial) points into a map. It is fed either one frame
at a time with :meth:`Mapper.insert` (points plus the sensor origin, as the thesis'
real-time loop does) or a whole cloud at once with :meth:`Mapper.build`.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any, ClassVar, Protocol, runtime_checkable

import numpy as np

from alte.errors import MapperError, ParameterError
from alte.types import as_points

__all__ = ["Cells", "Mapper", "Param", "check_points", "parse_params"]


@dataclass(frozen=True)
class Cells:
    """A map's cells as parallel arrays (one row per leaf / basis function).

    ``centers`` (K, 3) and ``sizes`` (K, 3) in metres: 2D maps put the cell height
    in ``centers[:, 2]`` and 0 in ``sizes[:, 2]``. ``value`` is the mapper's own
    quantity (mean height, occupancy probability, point count), ``occupied`` the
    binary state and ``level`` the tree depth (0 = root).
    """

    centers: np.ndarray
    sizes: np.ndarray
    value: np.ndarray
    occupied: np.ndarray
    level: np.ndarray

    def __len__(self) -> int:
        return int(self.centers.shape[0])

    def as_dict(self) -> dict[str, np.ndarray]:
        """Arrays by name, as written by ``alte map --export cells.npz``."""
        return {
            "centers": self.centers,
            "sizes": self.sizes,
            "value": self.value,
            "occupied": self.occupied,
            "level": self.level,
        }


@runtime_checkable
class Mapper(Protocol):
    """What every mapper offers; see ``alte.mappers.MAPPERS`` for the registry."""

    name: ClassVar[str]
    #: 2 for height maps (Quadtree, 2D-ALTE), 3 for volumetric maps.
    dims: ClassVar[int]
    #: True when ``insert`` updates only what the new frame touches.
    incremental: ClassVar[bool]

    @property
    def params(self) -> dict[str, Any]:
        """The validated parameters, defaults filled in."""
        ...

    def insert(self, points: np.ndarray, origin: np.ndarray) -> None:
        """Add one registered frame (N, 3) seen from sensor ``origin`` (3,)."""
        ...

    def build(self, points: np.ndarray, origins: np.ndarray | None = None) -> None:
        """Replace the map by one built from a whole cloud (origins: (3,) or (N, 3))."""
        ...

    def cells(self) -> Cells:
        """The map's leaves as arrays."""
        ...

    @property
    def basis_functions(self) -> int:
        """Number of cells a path planner must handle (thesis 5.2.1)."""
        ...

    @property
    def memory_bytes(self) -> int:
        """Bytes held by the map's data structures."""
        ...

    def corners(self) -> np.ndarray:
        """Corners of the occupied basis functions (M, 3): set B of thesis fig. 5.1."""
        ...


@dataclass(frozen=True)
class Param:
    """One mapper parameter: its type, default, a validity check and what it means."""

    kind: type
    default: Any
    check: Callable[[Any], bool] = lambda _v: True
    rule: str = ""
    help: str = ""


def _coerce(name: str, spec: Param, value: Any, owner: str) -> Any:
    if isinstance(value, str) and spec.kind is not str:
        if spec.kind is bool:
            lowered = value.strip().lower()
            if lowered not in {"true", "false", "1", "0", "yes", "no"}:
                raise ParameterError(f"{owner}: {name}={value!r} is not a boolean")
            return lowered in {"true", "1", "yes"}
        try:
            parsed = float(value) if spec.kind is int else spec.kind(value)
        except ValueError as err:
            raise ParameterError(
                f"{owner}: {name}={value!r} is not a valid {spec.kind.__name__}"
            ) from err
        if spec.kind is int and not parsed.is_integer():
            raise ParameterError(f"{owner}: {name}={value!r} must be an integer")
        value = parsed
    if spec.kind is int and isinstance(value, float) and not value.is_integer():
        raise ParameterError(f"{owner}: {name}={value!r} must be an integer")
    try:
        return spec.kind(value)
    except (TypeError, ValueError) as err:
        kind = spec.kind.__name__
        raise ParameterError(f"{owner}: {name}={value!r} is not a valid {kind}") from err


def parse_params(
    owner: str, specs: Mapping[str, Param], given: Mapping[str, Any]
) -> dict[str, Any]:
    """Validate ``given`` against ``specs``: unknown keys and out-of-range values raise."""
    unknown = sorted(set(given) - set(specs))
    if unknown:
        raise ParameterError(
            f"{owner}: unknown parameter(s) {', '.join(unknown)}; valid: {', '.join(sorted(specs))}"
        )
    out: dict[str, Any] = {}
    for name, spec in specs.items():
        value = _coerce(name, spec, given[name], owner) if name in given else spec.default
        if spec.kind is float and not np.isfinite(value):
            raise ParameterError(f"{owner}: {name}={value!r} must be finite")
        if not spec.check(value):
            raise ParameterError(f"{owner}: {name}={value!r} out of range ({spec.rule})")
        out[name] = value
    return out


def check_points(points: object, owner: str, name: str = "points") -> np.ndarray:
    """Return finite float64 (N, 3) points or raise :class:`MapperError` naming the problem."""
    return as_points(points, name, owner=owner, error=MapperError, finite=True)
