"""Shortest paths on the planning lattice: 26-neighbour graph + scipy's Dijkstra.

The graph holds only unblocked nodes' edges (built with numpy index arithmetic, one
array operation per neighbour offset); weights are Euclidean edge lengths. The search
is ``scipy.sparse.csgraph.dijkstra`` from the start node; the path is read back from
its predecessor array. Timings are split: graph build (classification, clearance,
edges) and search.
"""

from __future__ import annotations

import itertools
import time
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.sparse import coo_matrix, csr_matrix
from scipy.sparse.csgraph import dijkstra

from alte.lab.studies.planning.lattice import UNKNOWN, Lattice, PlanningMap, blocked_nodes

__all__ = ["OFFSETS", "PlanResult", "lattice_graph", "plan_path"]

#: The 13 neighbour offsets with a positive first non-zero component (the other 13 are
#: their opposites; the graph is undirected).
OFFSETS: tuple[tuple[int, int, int], ...] = tuple(
    (i, j, k) for i, j, k in itertools.product((-1, 0, 1), repeat=3) if (i, j, k) > (0, 0, 0))


@dataclass(frozen=True, eq=False)
class PlanResult:
    """Outcome of one planning query.

    ``status``: ``found``, ``no_path`` (start and goal are in different free
    components), ``start_blocked`` or ``goal_blocked``. ``path`` (M, 3) runs from the
    exact start through lattice nodes to the exact goal (empty when none);
    ``length_m`` is NaN when no path exists. ``free_nodes`` counts unblocked nodes,
    ``unknown_nodes`` those the map does not know (before any policy).
    """

    status: str
    path: NDArray[np.float64]
    length_m: float
    straight_m: float
    build_s: float
    search_s: float
    nodes: int
    unknown_nodes: int
    free_nodes: int
    edges: int

    @property
    def found(self) -> bool:
        return self.status == "found"


def _slices(off: int, n: int) -> tuple[slice[int, int, None], slice[int, int, None]]:
    return (slice(0, n - off), slice(off, n)) if off >= 0 else (slice(-off, n), slice(0, n + off))


def lattice_graph(free: NDArray[np.bool_], step: float) -> csr_matrix[np.float64]:
    """Upper-triangular sparse graph of 26-neighbour edges between ``free`` (3D bool) nodes."""
    ids = np.arange(free.size, dtype=np.int64).reshape(free.shape)
    rows, cols, weights = [], [], []
    for off in OFFSETS:  # 13 array operations, one per neighbour direction
        src, dst = zip(*(_slices(o, n) for o, n in zip(off, free.shape, strict=True)),
                       strict=True)
        both = free[src] & free[dst]
        rows.append(ids[src][both])
        cols.append(ids[dst][both])
        weights.append(np.full(int(both.sum()), step * float(np.linalg.norm(off))))
    row, col, w = np.concatenate(rows), np.concatenate(cols), np.concatenate(weights)
    lo, hi = np.minimum(row, col), np.maximum(row, col)
    return coo_matrix((w, (lo, hi)), shape=(free.size, free.size)).tocsr()


def _walk(predecessors: NDArray[np.int32], start: int, goal: int) -> NDArray[np.int64]:
    """Node indices from start to goal, read back from Dijkstra's predecessor array."""
    chain = [goal]
    while chain[-1] != start:  # one step per path node (a few hundred), not per point
        chain.append(int(predecessors[chain[-1]]))
    return np.array(chain[::-1], dtype=np.int64)


def _polyline_length(path: NDArray[np.float64]) -> float:
    return float(np.linalg.norm(np.diff(path, axis=0), axis=1).sum())


def plan_path(pmap: PlanningMap, start: object, goal: object, *, bounds: object, step: float,
              clearance: float, unknown: str = "free") -> PlanResult:
    """Shortest lattice path from ``start`` to ``goal`` keeping ``clearance`` from the map.

    ``bounds`` (2, 3) is the planning domain, ``step`` (m) the lattice spacing,
    ``unknown`` the policy for space the map does not know (``"free"``/``"occupied"``).
    """
    t0 = time.perf_counter()
    lattice = Lattice.over(bounds, step)
    s_node, g_node = lattice.nearest(start, "start"), lattice.nearest(goal, "goal")
    blocked, states = blocked_nodes(lattice, pmap, clearance, unknown)
    free = ~blocked.reshape(lattice.shape)
    graph = lattice_graph(free, lattice.step)
    build_s = time.perf_counter() - t0
    a, b = (np.asarray(p, dtype=np.float64).reshape(3) for p in (start, goal))
    counts = {"nodes": lattice.size, "unknown_nodes": int((states == UNKNOWN).sum()),
              "free_nodes": int(free.sum()), "edges": int(graph.nnz)}
    straight = float(np.linalg.norm(b - a))
    status = "start_blocked" if blocked[s_node] else "goal_blocked" if blocked[g_node] else ""
    search_s, path = 0.0, np.empty((0, 3))
    if not status:
        t1 = time.perf_counter()
        # scipy-stubs accept only arrays as indices; scipy takes an int (1-D results).
        dist, pred = dijkstra(graph, directed=False, indices=s_node,  # type: ignore[call-overload]
                              return_predecessors=True)
        search_s = time.perf_counter() - t1
        status = "found" if np.isfinite(dist[g_node]) else "no_path"
        if status == "found":
            path = np.vstack([a, lattice.node_points(_walk(pred, s_node, g_node)), b])
            path = path[np.r_[True, (np.diff(path, axis=0) != 0).any(axis=1)]]
    length = _polyline_length(path) if status == "found" else float("nan")
    return PlanResult(status, path, length, straight, build_s, search_s, **counts)
