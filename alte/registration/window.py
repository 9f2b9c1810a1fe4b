"""Odometry poses re-aligned to the scans around them, as the frames stream.

Frame-to-model odometry (KISS-ICP) places each scan against the map of the scans
*before* it. The first scans meet a thin map, and every later pose inherits their
error: on the real ``balm_seq`` recording the first scan alone puts the whole cloud
several centimetres off. Once the ``window`` scans after scan ``i`` have arrived, scan
``i`` is aligned again (VGICP, small_gicp: Koide et al., ICRA 2021) to a Gaussian voxel
map of its neighbours on both sides, ``i - window .. i + window`` without ``i`` itself
(a scan always matches itself best), from its odometry pose. The neighbours before it
carry their re-aligned poses (one Gauss-Seidel sweep along the sequence).

Streaming: the stage holds ``2 * window + 1`` down-sampled scans and yields each
frame ``window`` scans after it arrived (the rest at the end). An alignment that does
not converge or matches fewer than ``min_fitness`` of the scan keeps the odometry pose.
"""

from __future__ import annotations

import time
from collections import deque
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from typing import Protocol

import numpy as np
from numpy.typing import NDArray

from alte.registration.settings import PoseCounts
from alte.types import Frame

__all__ = ["WindowScan", "window_poses"]

#: Scans down-sampled for the alignment at this fraction of the map voxel.
SOURCE_FRACTION = 0.25
#: Fewest points a down-sampled scan needs to be aligned.
MIN_POINTS = 20
#: Neighbours of a down-sampled point its covariance is estimated from (small_gicp's own
#: default; 20 costs a third more and gains nothing on ``balm_seq``).
NEIGHBOURS = 10


class Cloud(Protocol):
    """What is read of a small_gicp point cloud."""

    def size(self) -> int: ...


@dataclass
class WindowScan:
    """One scan in the window: the frame, its down-sampled cloud (a small_gicp cloud with
    covariances, ``None`` when too small) and its sensor pose (4x4)."""

    frame: Frame
    cloud: Cloud | None
    pose: NDArray[np.float64]


def _cloud(points: NDArray[np.float64], voxel: float) -> Cloud | None:
    import small_gicp

    if len(points) < MIN_POINTS:
        return None
    cloud, _ = small_gicp.preprocess_points(points, SOURCE_FRACTION * voxel,
                                            num_neighbors=NEIGHBOURS, num_threads=1)
    kept: Cloud = cloud
    return kept if kept.size() >= MIN_POINTS else None


def _realign(scans: list[WindowScan], centre: int, voxel: float, min_fitness: float) -> bool:
    """Align ``scans[centre]`` to the others' Gaussian voxel map; whether it moved."""
    import small_gicp

    scan = scans[centre]
    others = [s for k, s in enumerate(scans) if k != centre and s.cloud is not None]
    if scan.cloud is None or not others:
        return False
    target = small_gicp.GaussianVoxelMap(voxel)
    for other in others:
        target.insert(other.cloud, other.pose)
    result = small_gicp.align(target, scan.cloud, scan.pose, num_threads=1,
                              max_correspondence_distance=voxel)
    inliers = result.num_inliers / max(scan.cloud.size(), 1)
    if not result.converged or inliers < min_fitness:
        return False
    scan.pose = np.asarray(result.T_target_source, dtype=np.float64)
    return True


def window_poses(steps: Iterable[tuple[Frame, NDArray[np.float64]]], *, window: int,
                 voxel: float, min_fitness: float, counts: PoseCounts,
                 ) -> Iterator[tuple[Frame, NDArray[np.float64]]]:
    """``(frame, sensor pose)`` pairs with each pose re-aligned to the ``window`` scans on
    either side (module docstring); ``counts.realigned`` counts the poses that moved."""
    scans: deque[WindowScan] = deque()
    done = 0  # index in ``scans`` of the next scan to re-align; those before it are done
    for frame, pose in steps:
        began, cpu = time.perf_counter(), time.thread_time()
        scans.append(WindowScan(frame, _cloud(np.asarray(frame.points, dtype=np.float64),
                                              voxel), pose))
        ready = len(scans) - 1 - done >= window
        if ready:
            counts.realigned += _realign(list(scans), done, voxel, min_fitness)
            done += 1
        counts.seconds += time.perf_counter() - began
        counts.cpu_seconds += time.thread_time() - cpu
        if ready:
            scan = scans[done - 1]
            while done > window:
                scans.popleft()
                done -= 1
            yield scan.frame, scan.pose
    yield from _flush(scans, done, voxel, min_fitness, counts)


def _flush(scans: deque[WindowScan], done: int, voxel: float, min_fitness: float,
           counts: PoseCounts) -> Iterator[tuple[Frame, NDArray[np.float64]]]:
    """The scans still waiting at the end, re-aligned to what is left around them."""
    items = list(scans)
    for centre in range(done, len(items)):
        began, cpu = time.perf_counter(), time.thread_time()
        counts.realigned += _realign(items, centre, voxel, min_fitness)
        counts.seconds += time.perf_counter() - began
        counts.cpu_seconds += time.thread_time() - cpu
        yield items[centre].frame, items[centre].pose
