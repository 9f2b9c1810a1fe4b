"""The two Octomap backends side by side: our native tree against the C++ OctoMap library
(``pyoctomap``) on the same scans (the agreement test and the bench)."""

from __future__ import annotations

import time
from collections.abc import Iterable

import numpy as np
from numpy.typing import NDArray

from alte.mappers.octomap.mapper import Octomap, OctomapSettings

__all__ = ["compare_backends"]


def compare_backends(
    scans: Iterable[tuple[NDArray[np.float64], NDArray[np.float64]]], **params: float | str
) -> dict[str, float]:
    """Insert the same scans into both backends; Jaccard of occupied voxels, leaves, times.

    Times cover every ``insert`` (pyoctomap's per-point Python-to-C++ copy is part of
    the reference time) plus the final leaf count (native: pruning; reference: C++
    ``getNumLeafNodes``); numba compilation is excluded by a warm-up insert.
    """
    native, reference, warm = (
        Octomap(None, record=OctomapSettings.parse({**params, "backend": backend}))
        for backend in ("native", "reference", "native"))  # warm: the numba kernels, untimed
    warm.insert(np.ones((1, 3)), np.zeros(3))
    _ = warm.basis_functions
    times = {"native": 0.0, "reference": 0.0}
    for points, origin in scans:
        for key, mapper in (("native", native), ("reference", reference)):
            start = time.perf_counter()
            mapper.insert(points, origin)
            times[key] += time.perf_counter() - start
    counts = {}
    for key, mapper in (("native", native), ("reference", reference)):
        start = time.perf_counter()
        counts[key] = mapper.basis_functions
        times[key] += time.perf_counter() - start
    a, b = native.occupied_voxels(), reference.occupied_voxels()
    union = np.union1d(a, b).size
    return {
        "jaccard": np.intersect1d(a, b, assume_unique=True).size / union if union else 1.0,
        "leaf_count_native": counts["native"],
        "leaf_count_reference": counts["reference"],
        "time_native_s": times["native"],
        "time_reference_s": times["reference"],
    }
