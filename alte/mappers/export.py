"""A map's cells to a file: ``.npz`` (the cells as arrays) or the mapper's native format."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from alte.errors import MapperError
from alte.fsutil import atomic_path, refuse_overwrite
from alte.mappers.base import Mapper

__all__ = ["check_export", "export_map"]


def check_export(path: Path, mapper: type[Mapper] | Mapper, overwrite: bool) -> None:
    """Fail before mapping when ``path`` cannot be written (type, support, exists)."""
    suffix = path.suffix.lower()
    if suffix not in mapper.exports:
        raise MapperError(f"export {path}: mapper {mapper.name!r} writes "
                          f"{', '.join(sorted(mapper.exports))} (not {suffix or 'no suffix'})",
                          setting="export.path")
    refuse_overwrite(path, overwrite)


def export_map(mapper: Mapper, path: Path, overwrite: bool = False,
               shift: NDArray[np.float64] | None = None) -> Path:
    """Write the cells (``.npz``, centres shifted back by ``shift``; a layer ``L`` as
    ``layer_L``) or the native format.

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
