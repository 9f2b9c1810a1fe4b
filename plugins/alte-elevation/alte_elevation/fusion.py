"""Per-cell height fusion: a 1-D Kalman update with a Mahalanobis gate, one scan at a time.

Each cell keeps the estimate of its height ``h`` and that estimate's variance ``v``.
A measurement ``z`` with variance ``r`` (:mod:`alte_elevation.noise`) updates it as in
ETH's ``elevation_mapping`` (``ElevationMap::add``):

    h <- (v z + r h) / (v + r),        v <- v r / (v + r)

unless it fails the gate ``|z - h| > threshold * sqrt(v + r)``: then it is not fused and
the cell's variance grows by ``multi_height_noise`` (a cell that keeps seeing other
heights, an edge, a moving object or an outlier, grows less sure). A cell seen for the
first time starts from its first point (``h = z``, ``v = r``).

Vectorised per scan: every point of a scan is gated against the cell's state before the
scan (a scan is one instant; a cell first seen in it, against its first point), and the
accepted ones are fused at once in information form, ``1/v' = 1/v + sum 1/r_i`` and
``h' = v' (h/v + sum z_i/r_i)``, which is exactly the sequence of the Kalman updates
above in any order. Two deliberate differences from ``elevation_mapping``: the gate
divides by the innovation's sigma ``sqrt(v + r)`` (``elevation_mapping`` by ``sqrt(v)``
alone, so once a cell's variance is below the point noise its test rejects most points
of the very surface it has converged on), and the gate uses the state before the scan.

Per cell the state also keeps the lowest and highest point, and the count, mean and sum
of squared deviations (Chan's merge) of every point's height with the sum of their
variances, from which :meth:`CellState.spread` gives the spread of the surface inside
the cell. These count the points the gate rejected too: the top of an obstacle is a
rejected point where the cell started on the ground, and the cell's surface spans both
(with the accepted heights only, the share of the lab terrains' true heights within two
sigma was 0.83-0.94 instead of 0.87-0.95; on the simulated urban ones 0.96-0.99 instead
of 0.98-0.99).
"""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np
from numpy.typing import NDArray

__all__ = ["CellState", "Gate", "fuse"]


@dataclass(frozen=True)
class Gate:
    """The fusion's two constants: the Mahalanobis ``threshold`` and the variance added to
    a cell per rejected point (``multi_height_noise``, m^2)."""

    threshold: float = 2.5
    multi_height_noise: float = 0.003**2


@dataclass(frozen=True)
class CellState:
    """The cells, sorted by ``keys`` (int64), with one value per cell in every array."""

    keys: NDArray[np.int64]
    height: NDArray[np.float64]
    variance: NDArray[np.float64]
    low: NDArray[np.float64]
    high: NDArray[np.float64]
    points: NDArray[np.float64]
    mean: NDArray[np.float64]
    m2: NDArray[np.float64]
    noise: NDArray[np.float64]

    @classmethod
    def empty(cls) -> CellState:
        """No cell."""
        return cls(np.empty(0, np.int64), *(np.empty(0) for _ in range(len(fields(cls)) - 1)))

    def __len__(self) -> int:
        return len(self.keys)

    @property
    def nbytes(self) -> int:
        """Bytes of the arrays."""
        return sum(getattr(self, f.name).nbytes for f in fields(self))

    def spread(self) -> NDArray[np.float64]:
        """Per cell, the variance of its points' heights beyond their own noise: the sample
        variance less the mean point variance, at least 0 (0 for a single point)."""
        n = np.maximum(self.points, 1.0)
        return np.maximum(self.m2 / n - self.noise / n, 0.0)


def _sums(inv: NDArray[np.intp], size: int, *values: NDArray[np.float64]
          ) -> list[NDArray[np.float64]]:
    return [np.bincount(inv, v, minlength=size).astype(np.float64) for v in values]


def _extremes(inv: NDArray[np.intp], z: NDArray[np.float64], size: int
              ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Lowest and highest ``z`` per cell index ``inv`` (every index 0..size-1 present)."""
    order = np.argsort(inv, kind="stable")
    starts = np.searchsorted(inv[order], np.arange(size))
    return np.minimum.reduceat(z[order], starts), np.maximum.reduceat(z[order], starts)


def fuse(state: CellState, keys: NDArray[np.int64], z: NDArray[np.float64],
         r: NDArray[np.float64], gate: Gate) -> CellState:
    """``state`` after one scan: points with cell ``keys``, heights ``z`` and variances
    ``r`` (module docstring)."""
    if len(keys) == 0:
        return state
    ukeys, first, inv = np.unique(keys, return_index=True, return_inverse=True)
    m = len(ukeys)
    pos = np.minimum(np.searchsorted(state.keys, ukeys), max(len(state) - 1, 0))
    old = (state.keys[pos] == ukeys) if len(state) else np.zeros(m, bool)
    # Prior per cell: its state, or for a new cell its first point of the scan.
    h0 = np.where(old, state.height[pos] if len(state) else 0.0, z[first])
    v0 = np.where(old, state.variance[pos] if len(state) else 1.0, r[first])
    starts = np.zeros(len(z), bool)
    starts[first[~old]] = True
    accept = ~starts & (np.abs(z - h0[inv]) <= gate.threshold * np.sqrt(v0[inv] + r))
    w = np.where(accept, 1.0 / r, 0.0)
    sw, sz, nrej, npts, zs, rs = _sums(inv, m, w, w * z, (~accept & ~starts).astype(float),
                                       np.ones(len(z)), z, r)
    var = 1.0 / (1.0 / v0 + sw)
    height = var * (h0 / v0 + sz)
    var = var + nrej * gate.multi_height_noise
    low, high = _extremes(inv, z, m)
    mb = zs / npts  # every cell of the scan has a point
    (m2b,) = _sums(inv, m, (z - mb[inv]) ** 2)
    return _merge(state, ukeys, old, pos, {
        "height": height, "variance": var, "low": low, "high": high, "points": npts,
        "mean": mb, "m2": m2b, "noise": rs})


def _places(state: CellState, ukeys: NDArray[np.int64], new: NDArray[np.bool_]
            ) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
    """Where the state's cells and the scan's new cells go in the merged, sorted arrays
    (``np.insert``'s order: a new cell before the old one its key precedes)."""
    at = np.searchsorted(state.keys, ukeys[new])
    kept = np.arange(len(state))
    return kept + np.searchsorted(at, kept, side="right"), at + np.arange(len(at))


def _merge(state: CellState, ukeys: NDArray[np.int64], old: NDArray[np.bool_],
           pos: NDArray[np.intp], scan: dict[str, NDArray[np.float64]]) -> CellState:
    """The state with the scan's cells: existing ones updated, new ones inserted in order
    (each array written once into its merged place: no copy, no ``np.insert`` per array)."""
    rows, new = pos[old], ~old
    values = {f.name: getattr(state, f.name) for f in fields(state)}
    na, nb = values["points"][rows], scan["points"][old]
    n = na + nb
    delta = scan["mean"][old] - values["mean"][rows]
    updated = {
        "height": scan["height"][old], "variance": scan["variance"][old],
        "low": np.minimum(values["low"][rows], scan["low"][old]),
        "high": np.maximum(values["high"][rows], scan["high"][old]),
        "points": n, "mean": values["mean"][rows] + delta * nb / n,
        "m2": values["m2"][rows] + scan["m2"][old] + delta**2 * na * nb / n,
        "noise": values["noise"][rows] + scan["noise"][old]}
    kept, put = _places(state, ukeys, new)
    merged = {"keys": ukeys[new], **{k: v[new] for k, v in scan.items()}}
    out = {}
    for name, before in values.items():
        array = np.empty(len(kept) + len(put), dtype=before.dtype)
        array[kept] = before
        if name in updated:
            array[kept[rows]] = updated[name]
        array[put] = merged[name]
        out[name] = array
    return CellState(**out)
