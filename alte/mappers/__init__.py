"""The terrain mappers: the contract (:mod:`~alte.mappers.api`), the thesis' four, the
registry that resolves every name (:mod:`~alte.mappers.registry`), and map export."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from alte.errors import MapperError
from alte.fsutil import atomic_path, refuse_overwrite
from alte.mappers import registry
from alte.mappers.alte2d import Alte2D
from alte.mappers.alte3d import Alte3D
from alte.mappers.base import VARIANCE, CellCounts, Cells, Cost, Feed, Mapper
from alte.mappers.domain import Domain, DomainUse
from alte.mappers.octomap import Octomap
from alte.mappers.quadtree import Quadtree

__all__ = ["VARIANCE", "Alte2D", "Alte3D", "CellCounts", "Cells", "Cost", "Domain", "DomainUse",
           "Feed", "Mapper", "Octomap", "Quadtree", "check_export", "export_map", "make_mapper",
           "registry"]

#: A mapper by class or by registered name, with its parameters (:func:`registry.create`).
make_mapper = registry.create


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
