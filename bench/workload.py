"""Benchmark inputs: the simulated terrains, registered once per process, and tiled clouds.

A :class:`Workload` is what the thesis' experiments feed the mappers: per kept frame
the registered, grid-averaged points and the sensor origin, and the merged cloud
(set A of the Hausdorff metrics). Full mode reads the whole mission from
``data/NAME`` (simulated on first use); quick mode simulates a few scans into
``data/bench_quick/NAME`` so the real terrain folders are never replaced.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from alte.errors import ParameterError

__all__ = ["QUICK_FRAMES", "Points", "Scan", "Workload", "load_workload", "tile_points",
           "workload_dir"]

#: float64 points (N, 3), or a sensor origin (3,).
Points = NDArray[np.float64]
#: One frame as the mappers insert it: registered points (N, 3) and the sensor origin (3,).
Scan = tuple[Points, Points]

#: Scans simulated per terrain in quick mode.
QUICK_FRAMES = 6


@dataclass(frozen=True, eq=False)
class Workload:
    """One terrain ready for mapping: frames ``(points, origin)``, merged cloud, control box."""

    name: str
    frames: list[Scan]
    cloud: Points
    bounds: NDArray[np.float64]
    voxel: float

    @property
    def frame_points(self) -> int:
        """Points over all frames (what incremental mappers insert)."""
        return int(sum(len(p) for p, _ in self.frames))

    def stacked(self) -> tuple[Points, Points]:
        """All frame points (P, 3) and each point's sensor origin (P, 3), frame order kept."""
        pts = np.vstack([p for p, _ in self.frames])
        origins = np.repeat(np.array([o for _, o in self.frames]),
                            [len(p) for p, _ in self.frames], axis=0)
        return pts, origins


def workload_dir(data_dir: str | Path, quick: bool) -> Path:
    """Where the terrains of this mode live."""
    return Path(data_dir) / "bench_quick" if quick else Path(data_dir)


def load_workload(terrain: str, data_dir: str | Path, *, quick: bool = False,
                  progress: bool = False) -> Workload:
    """Simulate ``terrain`` if missing and register it through the pipeline as the studies
    do (:func:`alte.lab.studies.experiments.terrain`, cached beside the terrains); quick mode
    simulates :data:`QUICK_FRAMES` scans evenly spaced over the mission."""
    from alte.lab.studies.experiments import terrain as registered_terrain

    data = registered_terrain(terrain, workload_dir(data_dir, quick),
                              frames=QUICK_FRAMES if quick else None, progress=progress)
    scans = [(np.array(f.points), np.asarray(f.origin, float)) for f in data.frames()]
    box = data.spec.crop if data.spec.crop is not None else data.bounds()
    assert data.spec.voxel is not None, "a terrain folder gives its registration voxel"
    return Workload(terrain, scans, np.array(data.cloud), np.asarray(box.values(), float),
                    float(data.spec.voxel))


def tile_points(points: Points, count: int, *extra: Points) -> list[Points]:
    """``count`` rows of ``points`` (N, 3): evenly subsampled, or tiled side by side in x/y.

    Copies are shifted by whole multiples of the cloud's x/y extent (plus 1 m), so
    tiles never overlap and every copy has the terrain's own density. ``extra``
    arrays (N, 3), e.g. per-point sensor origins, get the same shifts and selection.
    Rows keep their order, so runs of equal origins (scans) stay contiguous.
    """
    pts = np.asarray(points, dtype=np.float64)
    if count < 1 or len(pts) == 0:
        raise ParameterError(f"tile_points: need count >= 1 and points, got {count}, {len(pts)}")
    copies = math.ceil(count / len(pts))
    side = math.ceil(math.sqrt(copies))
    step = np.ptp(pts[:, :2], axis=0) + 1.0
    shift = np.zeros((copies, 3))
    shift[:, 0] = np.arange(copies) % side * step[0]
    shift[:, 1] = np.arange(copies) // side * step[1]
    keep = np.round(np.linspace(0, copies * len(pts) - 1, count)).astype(np.int64)
    tile, row = np.divmod(keep, len(pts))
    return [np.asarray(arr, dtype=np.float64)[row] + shift[tile] for arr in (pts, *extra)]
