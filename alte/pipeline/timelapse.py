"""A mapper applied over a mission, frame by frame (thesis figs. 3.3, 3.7, 3.14, 3.17).

:func:`timelapse` inserts registered frames one at a time, records the number of
basis functions after every frame and keeps the map's cells at a few evenly spaced
moments, so a notebook can draw the map growing during the flight.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from tqdm.auto import tqdm

from alte.errors import MapperError
from alte.mappers.base import Cells, Mapper

__all__ = ["Snapshot", "Timelapse", "cube_domain", "snapshot_indices", "square_domain",
           "timelapse"]


@dataclass(frozen=True)
class Snapshot:
    """The map after frame ``frame`` (0-based) at mission time ``time`` (s)."""

    frame: int
    time: float
    cells: Cells
    basis_functions: int


@dataclass(eq=False)
class Timelapse:
    """Per frame: time (s), basis functions, points inserted and seconds inside ``insert``."""

    mapper: str
    times: np.ndarray
    basis_functions: np.ndarray
    points: np.ndarray
    elapsed_s: np.ndarray
    snapshots: list[Snapshot] = field(default_factory=list)

    def summary(self) -> dict[str, Any]:
        """JSON-ready totals for ``save_results``."""
        return {
            "frames": len(self.times),
            "points": int(self.points.sum()),
            "elapsed_s": float(self.elapsed_s.sum()),
            "basis_functions": int(self.basis_functions[-1]) if len(self.times) else 0,
            "snapshot_times_s": [s.time for s in self.snapshots],
            "snapshot_basis_functions": [s.basis_functions for s in self.snapshots],
        }


def snapshot_indices(total: int, snapshots: int) -> np.ndarray:
    """``snapshots`` frame indices evenly spaced over ``total`` frames, ending at the last."""
    if snapshots < 1:
        raise MapperError(f"timelapse: snapshots={snapshots} must be >= 1")
    if total < 1:
        return np.empty(0, np.int64)
    return np.unique(np.round(np.linspace(0, total - 1, snapshots + 1)[1:]).astype(np.int64))


def square_domain(bounds: np.ndarray) -> str:
    """``"xmin,ymin,size"`` of the square over the x/y extent of ``bounds`` (2, 3) or (6,)."""
    box = np.asarray(bounds, dtype=np.float64).reshape(2, 3)
    size = float((box[1, :2] - box[0, :2]).max())
    if not np.isfinite(box).all() or size <= 0:
        raise MapperError(f"square_domain: bounds {box.tolist()} have no x/y extent")
    return f"{float(box[0, 0])!r},{float(box[0, 1])!r},{size!r}"


def cube_domain(bounds: np.ndarray) -> str:
    """``"xmin,ymin,zmin,size"`` of the cube over ``bounds`` (2, 3) or (6,) (3D mappers)."""
    box = np.asarray(bounds, dtype=np.float64).reshape(2, 3)
    size = float((box[1] - box[0]).max())
    if not np.isfinite(box).all() or size <= 0:
        raise MapperError(f"cube_domain: bounds {box.tolist()} have no extent")
    return ",".join(repr(float(v)) for v in (*box[0], size))


def timelapse(mapper: Mapper, frames: Sequence[tuple[np.ndarray, np.ndarray]],
              times: Sequence[float] | None = None, snapshots: int = 4,
              progress: bool = True) -> Timelapse:
    """Insert ``frames`` (points, origin) one by one; snapshot the cells ``snapshots`` times.

    ``times`` (s, one per frame) default to the frame index. Only ``insert`` is timed
    (thesis 5.2.1). The basis functions are counted after every frame, which costs
    one traversal of the map per frame (untimed).
    """
    stamps = np.arange(len(frames), dtype=np.float64) if times is None else np.asarray(
        times, dtype=np.float64)
    if stamps.shape != (len(frames),):
        raise MapperError(f"timelapse: {len(stamps)} times for {len(frames)} frames")
    keep = set(snapshot_indices(len(frames), snapshots).tolist())
    counts = np.zeros(len(frames), np.int64)
    points = np.zeros(len(frames), np.int64)
    elapsed = np.zeros(len(frames))
    shots: list[Snapshot] = []
    for i, (pts, origin) in enumerate(tqdm(frames, desc=mapper.name, unit="frame",
                                           disable=not progress, leave=False)):
        start = time.perf_counter()
        mapper.insert(pts, origin)
        elapsed[i] = time.perf_counter() - start
        points[i] = len(pts)
        counts[i] = mapper.basis_functions
        if i in keep:
            shots.append(Snapshot(i, float(stamps[i]), mapper.cells(), int(counts[i])))
    return Timelapse(mapper.name, stamps, counts, points, elapsed, shots)
