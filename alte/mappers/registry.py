"""The registry of the four terrain mappers (:data:`MAPPERS`, by name) and map export."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from alte.errors import MapperError
from alte.fsutil import atomic_path, refuse_overwrite
from alte.mappers.alte2d import Alte2D
from alte.mappers.alte3d import Alte3D
from alte.mappers.base import Mapper
from alte.mappers.domain import Domain
from alte.mappers.octomap import Octomap
from alte.mappers.quadtree import Quadtree
from alte.params import Record

__all__ = ["MAPPERS", "MapperClass", "check_export", "export_map", "make_mapper",
           "mapper_class"]

MapperClass = type[Quadtree] | type[Octomap] | type[Alte2D] | type[Alte3D]

#: Every mapper by the name the CLI, sweeps and notebooks use.
MAPPERS: dict[str, MapperClass] = {
    "quadtree": Quadtree,
    "octomap": Octomap,
    "alte2d": Alte2D,
    "alte3d": Alte3D,
}


def mapper_class(name: str) -> MapperClass:
    """The class registered as ``name``; an unknown name lists the valid ones."""
    try:
        return MAPPERS[name]
    except KeyError as err:
        raise MapperError(f"unknown mapper {name!r}; valid: {', '.join(MAPPERS)}") from err


def make_mapper(name: str, params: Mapping[str, object] | Record | None = None, /, *,
                domain: Domain | None = None, **given: object) -> Mapper:
    """Construct the mapper registered as ``name`` with validated ``params`` (a mapping or
    record, and/or keywords) and, where the mapper uses one, its ``domain``. A record of
    the mapper's own ``Params`` with no keywords is used as it is, not parsed again."""
    cls = mapper_class(name)
    if isinstance(params, cls.Params) and not given:
        return cls(domain, record=params)
    merged = params.as_dict() if isinstance(params, Record) else dict(params or {})
    return cls(domain, **{**merged, **given})


def check_export(path: Path, mapper: type[Mapper] | Mapper, overwrite: bool) -> None:
    """Fail before mapping when ``path`` cannot be written (type, support, exists)."""
    suffix = path.suffix.lower()
    if suffix not in mapper.exports:
        raise MapperError(f"--export {path}: mapper {mapper.name!r} writes "
                          f"{', '.join(sorted(mapper.exports))} (not {suffix or 'no suffix'})")
    refuse_overwrite(path, overwrite)


def export_map(mapper: Mapper, path: Path, overwrite: bool = False,
               shift: NDArray[np.float64] | None = None) -> Path:
    """Write the cells (``.npz``, centres shifted back by ``shift``) or the native format.

    ``shift`` is the local origin the points were mapped relative to; a native file
    (Octomap ``.bt``) stays in the mapper's local coordinates.
    """
    check_export(path, mapper, overwrite)
    if path.suffix.lower() != ".npz":
        return mapper.write_native(path, overwrite=overwrite)
    arrays = mapper.cells().as_dict()
    if shift is not None:
        arrays["centers"] = arrays["centers"] + np.asarray(shift, dtype=np.float64)
    with atomic_path(path, overwrite=overwrite) as tmp, tmp.open("wb") as fh:
        np.savez(fh, allow_pickle=False, **arrays)  # numeric arrays only
    return path
