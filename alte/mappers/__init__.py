"""The four terrain mappers, registered by name in :data:`MAPPERS`."""

from __future__ import annotations

from typing import Any

from alte.errors import MapperError
from alte.mappers.alte2d import Alte2D
from alte.mappers.alte3d import Alte3D
from alte.mappers.base import Cells, Mapper, Param
from alte.mappers.octomap import Octomap
from alte.mappers.quadtree import Quadtree

__all__ = ["MAPPERS", "Alte2D", "Alte3D", "Cells", "Mapper", "Octomap", "Param", "Quadtree",
           "make_mapper"]

MAPPERS: dict[str, type] = {
    "quadtree": Quadtree,
    "octomap": Octomap,
    "alte2d": Alte2D,
    "alte3d": Alte3D,
}


def make_mapper(name: str, **params: Any) -> Mapper:
    """Construct the mapper registered as ``name`` with validated ``params``."""
    try:
        cls = MAPPERS[name]
    except KeyError as err:
        raise MapperError(f"unknown mapper {name!r}; valid: {', '.join(MAPPERS)}") from err
    return cls(**params)
