"""Quadtree occupancy grid (thesis 3.1, after Pankratov's MATLAB ``quadtree``).

A cell splits into four while it holds more than ``max_points`` points (thesis
values 25-1000) and is shallower than ``max_depth`` (a guard against duplicate
points, which no split can separate). Leaves then become free or occupied from the
heights of their points above the ground plane:

* ``occupancy="mean"`` (default): occupied when the *mean* height above the plane
  exceeds ``height_threshold``. A large leaf that is only partly covered by an
  obstacle averages it away, which is the free space inside obstacles of the
  thesis' figure 4.17 and why coarse settings lose fidelity (table 5.7).
* ``occupancy="max"``: occupied when any point rises over the threshold
  (conservative, but a single outlier marks a whole leaf).

The ground plane is a parameter, fixed for the whole map: ``ground="z0"`` (the plane
``z = z0``), ``ground="a,b,c,d"`` (``a x + b y + c z + d = 0``) or ``ground="fit"``
(:func:`alte.ground.fit_plane_msac` on the cloud; :meth:`Quadtree.build` only, since
refitting per frame would change heights already inserted). The core works on the
plane as an array, :attr:`Quadtree.plane`.

The thesis' Quadtree runs once on the final cloud (``default_feed`` is batch); this one
also inserts frame by frame, revisiting only the cells the frame touches, and ends with
the same map as the batch build (the split rule depends on a cell's own count only). Leaves without
points (siblings of split cells) are *unknown*: NaN height and value, not occupied.

Cells: ``centers[:, 2]`` is the leaf's mean z, ``value`` the thresholded statistic
(mean or max height above the plane). ``basis_functions`` counts every leaf (free,
occupied and unknown: the variable-size occupancy grid a planner walks);
``corners()`` gives the 4 corners of every known leaf at its mean z.

Memory: inserted frames keep the statistics of every non-empty cell down to
``max_depth`` (needed to split a leaf later). A build keeps the partition's cells
only (the root and the children of split cells: 5 % of them on sim_lan_2 at
``max_points`` 25) and the sorted points' keys and values, from which an insertion
after the build first fills in the rest; ``memory_bytes`` counts what is held.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import ClassVar, Literal, get_args

import numba
import numpy as np
from numpy.typing import NDArray

from alte._numba import CLOUD_MIN, threads_for
from alte.errors import AlteError, MapperError
from alte.mappers.base import Feed, renamed
from alte.mappers.domain import Domain
from alte.mappers.quad.quadmap import LeafValues, QuadMap, Rows, plane_height
from alte.params import Record, param

__all__ = ["Quadtree", "QuadtreeSettings", "parse_ground"]

Occupancy = Literal["mean", "max"]
RULES: tuple[str, ...] = get_args(Occupancy)


def parse_ground(text: str) -> NDArray[np.float64] | None:
    """``"z0"`` -> plane (0, 0, 1, -z0); ``"a,b,c,d"`` -> that plane; ``"fit"`` -> None."""
    if text.strip().lower() == "fit":
        return None
    values = np.array([float(v) for v in text.split(",")])
    if values.shape == (1,):
        values = np.array([0.0, 0.0, 1.0, -values[0]])
    plane_height(values, np.zeros((1, 2)))  # raises ValueError when unusable
    return values


@numba.njit(cache=True, parallel=True)
def _z_and_above(points: NDArray[np.float64], plane: NDArray[np.float64]) -> NDArray[np.float64]:
    """``z, z - plane_height(plane, xy)`` of every point, in one pass (the same arithmetic,
    in the same order, as the numpy expression; every thread for a cloud). Allocated
    here: numpy asks the kernel for huge pages for arrays from 4 MiB, and on this kind
    of machine their first touch (zeroing, compaction) costs more than the pass itself."""
    a, b, c, d = plane[0], plane[1], plane[2], plane[3]
    out = np.empty((points.shape[0], 2))
    for i in numba.prange(points.shape[0]):
        out[i, 0] = points[i, 2]
        out[i, 1] = points[i, 2] - -(a * points[i, 0] + b * points[i, 1] + d) / c
    return out


def _ground_ok(text: str) -> bool:
    try:
        parse_ground(text)
    except ValueError:
        return False
    return True


@dataclass(frozen=True)
class QuadtreeSettings(Record):
    """Quadtree parameters (module docstring)."""

    OWNER: ClassVar[str] = "quadtree"
    max_points: int = param(200, lambda v: v >= 1, "max_points >= 1",
                            "split a cell holding more points than this")
    max_depth: int = param(12, lambda v: 0 <= v <= 24, "0 <= max_depth <= 24",
                           "deepest level (guard against duplicate points)")
    height_threshold: float = param(0.5, lambda v: v >= 0, "height_threshold >= 0",
                                    "m above the ground plane for an occupied leaf")
    occupancy: Occupancy = param("mean",
                                 help="statistic of the leaf's heights compared with the threshold")
    ground: str = param("0", _ground_ok, "z0, a,b,c,d (non-vertical) or fit",
                        "ground plane the heights are measured from")


class Quadtree(QuadMap):
    """Point-count quadtree with a height-above-ground occupancy rule (module docstring)."""

    name: ClassVar[str] = "quadtree"
    title: ClassVar[str] = "Quadtree"
    default_feed: ClassVar[Feed] = Feed.BATCH
    Settings: ClassVar[type[Record]] = QuadtreeSettings
    #: Contract v1's first name of :attr:`Settings` (deprecated; still read by old code).
    Params: ClassVar[type[Record]] = QuadtreeSettings
    #: The leaves keep the mean and the maximum height above the plane: the rule and the
    #: threshold only read them.
    view_params: ClassVar[frozenset[str]] = frozenset({"occupancy", "height_threshold"})
    settings_grid: ClassVar[Mapping[str, tuple[object, ...]]] = {
        "max_points": (10, 25, 50, 100, 150, 200, 350, 500, 1000, 2000)}
    _NVALUES: ClassVar[int] = 2  # z, height above the plane

    def __init__(self, domain: Domain | None = None, *, record: Record | None = None,
                 **given: object) -> None:
        super().__init__(domain, record=record, **given)
        #: Ground plane (a, b, c, d); None until ``build`` fits it (``ground="fit"``).
        self.plane: NDArray[np.float64] | None = parse_ground(self._params["ground"])

    @property
    def depth(self) -> int:
        """``max_depth``: the deepest level."""
        return int(self._params["max_depth"])

    def insert(self, points: NDArray[np.float64], origin: NDArray[np.float64]) -> None:
        """Add one frame; needs a fixed ground plane (not ``ground=fit``)."""
        if self.plane is None:
            raise MapperError("quadtree: ground=fit needs the whole cloud (build); give "
                              "insert a fixed plane, e.g. ground=0 or ground=a,b,c,d")
        super().insert(points, origin)

    def build(self, points: NDArray[np.float64],
              origins: NDArray[np.float64] | None = None) -> None:
        """Build from a whole cloud, fitting the ground plane first when ``ground=fit``."""
        if self._params["ground"].strip().lower() == "fit" and len(np.atleast_2d(points)) >= 3:
            from alte.ground import fit_plane_msac

            try:
                fit = fit_plane_msac(np.asarray(points, dtype=np.float64),
                                     reference_normal=np.array([0.0, 0.0, 1.0]), max_angle_deg=30)
            except AlteError as err:
                raise MapperError(f"quadtree: {err}") from err
            self.plane = np.r_[fit.normal, fit.d]
        elif self.plane is None:
            raise MapperError("quadtree: ground=fit needs at least 3 points")
        super().build(points, origins)

    def _values(self, points: NDArray[np.float64]) -> NDArray[np.float64]:
        assert self.plane is not None  # insert and build refuse to go on without one
        with threads_for(len(points), CLOUD_MIN):
            values: NDArray[np.float64] = _z_and_above(points, self.plane)
        return values

    def _split(self, level: int, rows: Rows) -> NDArray[np.bool_]:
        n = self.stats.column(level, "n")[rows]
        split: NDArray[np.bool_] = (n > self._split_above()) & (level < self.depth)
        return split

    def _split_above(self) -> float:
        return float(self._params["max_points"])

    def _leaf_values(self, level: NDArray[np.int64], rows: NDArray[np.int64],
                     centers: NDArray[np.float64]) -> LeafValues:
        z = self.leaf_stat(level, rows, "mean", 0)
        value = self.leaf_stat(level, rows, self._params["occupancy"], 1)
        occupied = np.isfinite(value) & (value > self._params["height_threshold"])
        return z, value, occupied


def __getattr__(name: str) -> object:
    """``QuadtreeParams``: the first name of :class:`QuadtreeSettings` (deprecated)."""
    return renamed(__name__, name, {"QuadtreeParams": lambda: QuadtreeSettings})
