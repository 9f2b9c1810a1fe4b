"""The root cell of a map: a cube (3D mappers) whose x/y square is the root of a 2D map.

Thesis 3.3: "an overall domain is defined" before the adaptive partition starts. A
:class:`Domain` is that cell, ``[xmin, xmin + size] x [ymin, ymin + size] x [zmin, zmin +
size]`` (closed). Where it comes from is a policy of the pipeline (explicit, the
control volume, or the data); :meth:`Domain.over` is the one rule that turns a box
into a domain, so every entry point anchors maps the same way.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from alte.errors import MapperError, ParameterError
from alte.types import Box, rows_all

__all__ = ["Domain", "DomainUse", "check_domain"]

#: Relative and absolute slack that keeps the box's upper points inside ``lo + size``.
_REL, _ABS = 1e-9, 1e-9


class DomainUse(enum.Enum):
    """How a mapper uses a domain (a capability the pipeline reads, never probes)."""

    #: The partition is anchored on it; ``insert`` needs it (3D-ALTE).
    REQUIRED = "required"
    #: Anchored on it when given, else grown from the data (Quadtree, 2D-ALTE).
    OPTIONAL = "optional"
    #: A fixed key space of its own (Octomap: 2^16 voxels per axis around 0).
    UNUSED = "unused"


@dataclass(frozen=True)
class Domain:
    """A cube anchored at its minimum corner; 2D mappers use its x/y square."""

    xmin: float
    ymin: float
    zmin: float
    size: float

    def __post_init__(self) -> None:
        values = [self.xmin, self.ymin, self.zmin, self.size]
        if not np.isfinite(values).all() or not self.size > 0:
            raise ParameterError(f"domain {values}: expected 4 finite numbers "
                                 "xmin,ymin,zmin,size with size > 0")
        for name, value in zip(("xmin", "ymin", "zmin", "size"), values, strict=True):
            object.__setattr__(self, name, float(value))

    @classmethod
    def over(cls, box: Box) -> Domain:
        """The cube anchored at ``box.lo`` whose edge covers the box's longest side."""
        extent = float(np.max(box.hi - box.lo))
        size = extent * (1 + _REL) + _ABS if extent > 0 else 1.0
        xmin, ymin, zmin = (float(v) for v in box.lo)
        return cls(xmin, ymin, zmin, size)

    @classmethod
    def parse(cls, text: str) -> Domain:
        """``"xmin,ymin,zmin,size"`` or, for 2D maps, ``"xmin,ymin,size"`` (zmin 0)."""
        try:
            values = [float(v) for v in text.split(",")]
        except ValueError as err:
            raise ParameterError(f"domain {text!r}: expected numbers xmin,ymin[,zmin],size") \
                from err
        if len(values) == 3:
            values.insert(2, 0.0)
        if len(values) != 4:
            raise ParameterError(f"domain {text!r}: expected xmin,ymin,size or "
                                 "xmin,ymin,zmin,size")
        return cls(*values)

    @property
    def lo(self) -> NDArray[np.float64]:
        """Minimum corner (3,)."""
        return np.array([self.xmin, self.ymin, self.zmin])

    @property
    def box(self) -> Box:
        """The cube as a :class:`~alte.types.Box`."""
        return Box(self.lo, self.lo + self.size)

    def inside(self, points: NDArray[np.float64], dims: int = 3) -> NDArray[np.bool_]:
        """Mask of the (N, 3) points in the closed cube (first ``dims`` axes only)."""
        rel = (np.asarray(points, dtype=np.float64)[:, :dims] - self.lo[:dims]) / self.size
        return rows_all((rel >= 0.0) & (rel <= 1.0))

    def text(self) -> str:
        """``"xmin,ymin,zmin,size"`` (round-trips through :meth:`parse`)."""
        return ",".join(repr(v) for v in (self.xmin, self.ymin, self.zmin, self.size))

    def as_dict(self) -> dict[str, float]:
        """JSON-ready form."""
        return {"xmin": self.xmin, "ymin": self.ymin, "zmin": self.zmin, "size": self.size}


def check_domain(owner: str, domain: object) -> Domain | None:
    """``domain`` when it is a :class:`Domain` or None; anything else is a typed error."""
    if domain is None or isinstance(domain, Domain):
        return domain
    raise MapperError(f"{owner}: domain must be an alte.mappers.Domain (or None), got "
                      f"{type(domain).__name__} {domain!r}; text parses with Domain.parse")
