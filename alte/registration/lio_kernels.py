"""numba kernels of the LIO's local map (:mod:`alte.registration.localmap`): plane fits
of many small neighbourhoods at once (centroid, covariance and its eigenvectors per row),
and the merge of two k-d trees' neighbour lists (:mod:`alte.registration.neighbours`).

numpy took five passes over an (N, k, 3) gather and a batched LAPACK ``eigh`` for the
3 x 3 covariances (a quarter of the LIO's CPU went to its plane fits, half of that to
``eigh``). Here one pass per row sums the neighbours' moments and cyclic Jacobi rotations
diagonalise the covariance: exact to rounding for a symmetric 3 x 3 (the off-diagonal
terms shrink quadratically, a few sweeps), with no call out per row. The two trees' lists
were merged by a stable ``argsort`` of them side by side (4 % of the LIO); each is sorted
already, so one merge pass does it. Between the filter's iterations a row keeps the neighbours
it was searched with when they provably have not changed (:func:`kept_nearest`).
Imported on first use: ``alte info`` and the other commands that import the odometry's
settings do not load numba.
"""

from __future__ import annotations

import numba
import numpy as np
from numpy.typing import NDArray

__all__ = ["kept_nearest", "merge_nearest", "plane_fits"]

#: Neighbours' distances (N, k; inf where missing) and rows (N, k).
_Found = tuple[NDArray[np.float64], NDArray[np.int64]]

_SWEEPS = 32
#: Margin (m) by which a kept row's neighbours must be nearer than any other point can
#: be: the rounding of distances measured in double precision is far below it.
MARGIN = 1e-9


@numba.njit(cache=True)
def _rotate(a: NDArray[np.float64], v: NDArray[np.float64], p: int, q: int) -> None:
    """One Jacobi rotation zeroing ``a[p, q]`` (``a`` symmetric), accumulated in ``v``."""
    apq = a[p, q]
    if apq == 0.0:
        return
    theta = (a[q, q] - a[p, p]) / (2.0 * apq)
    if abs(theta) > 1e150:
        t = 0.5 / theta
    else:
        t = 1.0 / (abs(theta) + np.sqrt(theta * theta + 1.0))
        if theta < 0.0:
            t = -t
    c = 1.0 / np.sqrt(t * t + 1.0)
    s = t * c
    for r in range(3):
        arp, arq = a[r, p], a[r, q]
        a[r, p], a[r, q] = c * arp - s * arq, s * arp + c * arq
    for r in range(3):
        apr, aqr = a[p, r], a[q, r]
        a[p, r], a[q, r] = c * apr - s * aqr, s * apr + c * aqr
    for r in range(3):
        vrp, vrq = v[r, p], v[r, q]
        v[r, p], v[r, q] = c * vrp - s * vrq, s * vrp + c * vrq


@numba.njit(cache=True)
def _eigen(a: NDArray[np.float64], v: NDArray[np.float64]) -> None:
    """``a`` (symmetric 3 x 3) diagonalised in place, its eigenvectors the columns of
    ``v`` (set to the identity first)."""
    v[:] = 0.0
    for r in range(3):
        v[r, r] = 1.0
    for _ in range(_SWEEPS):
        off = abs(a[0, 1]) + abs(a[0, 2]) + abs(a[1, 2])
        if off <= 1e-18 * (abs(a[0, 0]) + abs(a[1, 1]) + abs(a[2, 2])):
            break
        _rotate(a, v, 0, 1)
        _rotate(a, v, 0, 2)
        _rotate(a, v, 1, 2)


@numba.njit(cache=True)
def _moments(points: NDArray[np.float64], row: NDArray[np.int64], centre: NDArray[np.float64],
             a: NDArray[np.float64]) -> None:
    """The centroid of ``points[row]`` into ``centre`` and their covariance into ``a``."""
    k = row.shape[0]
    centre[:] = 0.0
    for j in range(k):
        for d in range(3):
            centre[d] += points[row[j], d]
    centre /= k
    a[:] = 0.0
    for j in range(k):
        for d in range(3):
            x = points[row[j], d] - centre[d]
            for e in range(d, 3):
                a[d, e] += x * (points[row[j], e] - centre[e])
    for d in range(3):
        for e in range(d, 3):
            a[d, e] /= k
            a[e, d] = a[d, e]


@numba.njit(cache=True)
def _order(x: float, y: float, z: float) -> tuple[int, int]:
    """The positions of the least and the middle of three values (ties: the first)."""
    low = 0 if x <= y and x <= z else (1 if y <= z else 2)
    rest = (1, 2) if low == 0 else ((0, 2) if low == 1 else (0, 1))
    values = (x, y, z)
    mid = rest[0] if values[rest[0]] <= values[rest[1]] else rest[1]
    return low, mid


@numba.njit(cache=True)
def plane_fits(points: NDArray[np.float64], idx: NDArray[np.int64], thickness: float,
               ) -> tuple[NDArray[np.bool_], NDArray[np.float64], NDArray[np.float64]]:
    """Per row of neighbour indices ``idx`` (N, k) into ``points``: whether they lie on a
    plane (spread along the normal under ``thickness``, along the second axis over three
    times it: not a line), the unit normal (the covariance's least eigenvector) and the
    centroid."""
    n = idx.shape[0]
    flat = np.zeros(n, np.bool_)
    normal, centre = np.zeros((n, 3)), np.zeros((n, 3))
    a, v = np.empty((3, 3)), np.empty((3, 3))
    for i in range(n):
        _moments(points, idx[i], centre[i], a)
        _eigen(a, v)
        low, mid = _order(a[0, 0], a[1, 1], a[2, 2])
        flat[i] = np.sqrt(max(a[low, low], 0.0)) < thickness \
            and np.sqrt(max(a[mid, mid], 0.0)) > 3.0 * thickness
        for c in range(3):  # element by element: no shape check to compile
            normal[i, c] = v[c, low]
    return flat, normal, centre


@numba.njit(cache=True)
def merge_nearest(first: _Found, second: _Found) -> _Found:
    """Per row, the ``k`` nearest of two neighbour lists each sorted by distance (ties:
    ``first``'s before ``second``'s, as a stable sort of the two side by side orders them)."""
    (d1, i1), (d2, i2) = first, second
    n, k = d1.shape
    dist, idx = np.empty((n, k)), np.empty((n, k), np.int64)
    for r in range(n):
        a = b = 0
        for j in range(k):
            if d1[r, a] <= d2[r, b]:
                dist[r, j], idx[r, j] = d1[r, a], i1[r, a]
                a += 1
            else:
                dist[r, j], idx[r, j] = d2[r, b], i2[r, b]
                b += 1
    return dist, idx


@numba.njit(cache=True)
def _measured(points: NDArray[np.float64], query: NDArray[np.float64], rows: NDArray[np.int64],
              bound: float, out: _Found) -> None:
    """The candidate ``rows`` sorted by their distance to ``query`` (a stable insertion
    sort) into ``out`` (distances, rows); beyond ``bound`` or missing: inf. Summed as
    pykdtree sums, so that a distance is the very one it returns."""
    dist, idx = out
    for j in range(len(rows)):
        e = np.inf
        if rows[j] < len(points):
            s = 0.0
            for c in range(3):
                d = query[c] - points[rows[j], c]
                s += d * d
            if s < bound * bound:  # pykdtree's test, on squared distances
                e = np.sqrt(s)
        t = j - 1
        while t >= 0 and dist[t] > e:
            dist[t + 1], idx[t + 1] = dist[t], idx[t]
            t -= 1
        dist[t + 1], idx[t + 1] = e, rows[j]


@numba.njit(cache=True)
def kept_nearest(points: NDArray[np.float64], query: NDArray[np.float64],
                 last: tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.int64]],
                 bound: float, k: int) -> tuple[NDArray[np.bool_], NDArray[np.float64],
                                                NDArray[np.int64]]:
    """Per query row, whether its ``k`` nearest are among the candidates of ``last``
    (per row the point searched from, the distances and rows of its ``m > k`` nearest),
    and then which, in order (:mod:`alte.registration.neighbours`): every other point was
    at least the last candidate's distance (or ``bound``) from there, so at least that
    minus the row's shift away now (less :data:`MARGIN`); equal distances are not kept."""
    anchor, near, rows = last
    n, m = rows.shape
    keep = np.zeros(n, np.bool_)
    dist, idx = np.empty((n, m)), np.empty((n, m), np.int64)
    for r in range(n):
        s = 0.0
        for c in range(3):
            d = query[r, c] - anchor[r, c]
            s += d * d
        far = (near[r, m - 1] if np.isfinite(near[r, m - 1]) else bound) - np.sqrt(s) - MARGIN
        _measured(points, query[r], rows[r], bound, (dist[r], idx[r]))
        ok = dist[r, k - 1] < far
        for j in range(k):
            ok = ok and dist[r, j + 1] > dist[r, j]
        keep[r] = ok
    return keep, dist[:, :k], idx[:, :k]
