"""The Octomap's machine-independent cost: the voxel steps of a scan's ray walks.

OctoMap's ``computeUpdate`` steps every ray from the sensor's key to its end key, one
voxel at a time; a scan's cost is those steps plus one end voxel per valid ray. The
native backend counts them as it walks (:mod:`~alte.mappers.octomap.scan`); the
reference backend, which walks in C++, gets them from :func:`scan_cost`.
"""

from __future__ import annotations

import numba
import numpy as np
from numpy.typing import NDArray

from alte.mappers.octree.raycast import prepare

__all__ = ["scan_cost", "skip_ray", "walk_limit", "walk_steps"]


@numba.njit(cache=True, inline="always")
def skip_ray(okey: NDArray[np.int64], k: NDArray[np.int64]) -> bool:
    """A ray is walked when its end key is valid and differs from the origin's."""
    return bool(k[0] < 0 or (k[0] == okey[0] and k[1] == okey[1] and k[2] == okey[2]))


@numba.njit(cache=True, inline="always")
def walk_limit(okey: NDArray[np.int64], k: NDArray[np.int64]) -> int:
    """The most voxels a ray to key ``k`` steps through (``|dk|_1`` and a margin)."""
    return int(abs(k[0] - okey[0]) + abs(k[1] - okey[1]) + abs(k[2] - okey[2]) + 5)


@numba.njit(cache=True)
def _steps(okey: NDArray[np.int64], ekeys: NDArray[np.int64]) -> int:
    """Voxel steps of the scan's walks (``|dk|_1`` of the valid ray ends)."""
    steps = 0
    for i in range(ekeys.shape[0]):
        if ekeys[i, 0] >= 0:
            steps += abs(ekeys[i, 0] - okey[0]) + abs(ekeys[i, 1] - okey[1]) + \
                abs(ekeys[i, 2] - okey[2])
    return steps


@numba.njit(cache=True)
def walk_steps(okey: NDArray[np.int64], ekeys: NDArray[np.int64]) -> tuple[int, int]:
    """The voxels a scan's walks step through (none when the origin is off the key space),
    and its ray steps: those plus one end voxel per valid ray."""
    ends = 0
    for i in range(ekeys.shape[0]):
        ends += ekeys[i, 0] >= 0
    steps = _steps(okey, ekeys) if okey.min() >= 0 else 0
    return steps, steps + ends


@numba.njit(cache=True)
def _prepared_cost(points: NDArray[np.float32], origin: NDArray[np.float32], res: float,
                   max_range: float) -> int:
    okey, _ends, ekeys, _hit = prepare(points, origin, res, max_range)
    return int(walk_steps(okey, ekeys)[1])


def scan_cost(points: NDArray[np.float32], origin: NDArray[np.float32], res: float,
              max_range: float) -> int:
    """Ray steps of one scan (float32 ``points`` and ``origin``), as :func:`scan_blocks`
    counts them into :attr:`ScanWork.steps`: for a backend that walks the rays itself."""
    return int(_prepared_cost(points, origin, res, max_range))
