"""2D grids of a map: a height raster classified free / occupied / unknown, as ROS messages.

* :func:`raster`: a map's leaves painted onto a regular grid at the finest leaf size
  (coarsened by powers of two to at most ``max_cells``). A 2D map gives each pixel the
  height of its leaf; a 3D map the top of the highest occupied leaf over it (the
  surface a descending vehicle meets), pixels under free leaves only being seen but
  surfaceless. Every known pixel is then classified by the landing criterion of
  :mod:`alte.ground.surface` (:class:`~alte.ground.surface.OccupancySettings`): free (0)
  where a vehicle can rest, occupied (100) where it cannot (an obstacle, a steep or
  rough patch, a column seen only as free space), unknown (-1) only where no leaf lies.
* :func:`occupancy_grid` (``nav_msgs/msg/OccupancyGrid``), :func:`grid_map`
  (``grid_map_msgs/msg/GridMap``, RViz's grid_map plugin: layers ``elevation`` and
  ``occupancy``, NaN where unknown) and :func:`foxglove_grid` (``foxglove_msgs/msg/Grid``,
  drawn natively by Foxglove's 3D panel: fields ``elevation`` float32 m, ``occupancy``
  int8 and ``red``/``green``/``blue``/``alpha`` uint8, the height in viridis with
  unknown pixels transparent, which Foxglove picks by default).

A 2D map whose cells carry layers (``Cells.layers``: the elevation map's ``variance``,
``min``, ``max``, ``count``) has them painted too (:attr:`Raster.layers`), each one more
``grid_map`` layer and one more float32 ``foxglove_msgs/msg/Grid`` field after ``alpha``
(NaN where unknown): a viewer can colour the grid by the map's own height variance.

The flat grids lie one cell below the lowest known height (:attr:`Raster.floor`; the
Foxglove grid half a cell lower still) so they never hide the map or the cloud.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from alte.errors import ParameterError
from alte.export.rosmsg import blank, header, pose, time_msg, typestore
from alte.ground.surface import OccupancySettings, classify_surface
from alte.mappers import Cells

if TYPE_CHECKING:  # rosbags declares its message classes' type for checkers only
    from rosbags.typesys.store import MsgType

__all__ = ["GRID_FIELDS", "Raster", "foxglove_grid", "grid_cells", "grid_fields", "grid_map",
           "height_colours", "occupancy_grid", "raster"]

_UINT8, _INT8, _FLOAT32 = 1, 2, 7
#: ``foxglove_msgs/msg/Grid`` fields: (name, byte offset, PackedElementField type).
GRID_FIELDS = (("elevation", 0, _FLOAT32), ("occupancy", 4, _INT8), ("red", 5, _UINT8),
               ("green", 6, _UINT8), ("blue", 7, _UINT8), ("alpha", 8, _UINT8))
_FORMATS = {_UINT8: "u1", _INT8: "i1", _FLOAT32: "<f4"}
_BASE = 9  # bytes of the GRID_FIELDS
_IDENTITY = np.array([0.0, 0.0, 0.0, 1.0])


def height_colours(z: NDArray[np.float64]) -> NDArray[np.float64]:
    """(N, 4) RGBA in 0..1, viridis over the heights' range (one colour when flat)."""
    from matplotlib import colormaps

    if not len(z):
        return np.empty((0, 4))
    lo, hi = float(np.min(z)), float(np.max(z))
    t = (z - lo) / (hi - lo) if hi > lo else np.full(len(z), 0.5)
    return np.asarray(colormaps["viridis"](t), dtype=np.float64)


@dataclass(frozen=True)
class Raster:
    """A map on a regular grid: row ``i`` is y, column ``j`` is x, cell (0, 0) has its
    lower-left corner at ``origin``; NaN height where no surface is known, occupancy
    0 free / 100 occupied / -1 unknown; ``layers``: the 2D map's cell layers by name,
    painted like the height (NaN where unknown)."""

    origin: NDArray[np.float64]
    resolution: float
    height: NDArray[np.float64]
    occupancy: NDArray[np.int8]
    layers: Mapping[str, NDArray[np.float64]] = field(default_factory=dict)

    @property
    def shape(self) -> tuple[int, int]:
        """(rows = cells along y, columns = cells along x)."""
        return (int(self.height.shape[0]), int(self.height.shape[1]))

    @property
    def floor(self) -> float:
        """Height of the flat grids: one cell below the lowest known height (0 if none)."""
        known = self.height[np.isfinite(self.height)]
        return float(known.min()) - self.resolution if known.size else 0.0


def _footprints(centers: NDArray[np.float64], edge: NDArray[np.float64], max_cells: int
                ) -> tuple[NDArray[np.float64], float, int, int]:
    """Lower-left corner, pixel size, rows and columns of the grid covering the leaves."""
    lo = (centers[:, :2] - edge[:, None] / 2).min(axis=0)
    hi = (centers[:, :2] + edge[:, None] / 2).max(axis=0)
    res = float(edge.min())
    while np.prod(np.ceil((hi - lo) / res - 1e-9)) > max_cells:
        res *= 2
    cols, rows = (int(v) for v in np.maximum(np.ceil((hi - lo) / res - 1e-9), 1))
    return lo, res, rows, cols


def _pixels(centers: NDArray[np.float64], edge: NDArray[np.float64], lo: NDArray[np.float64],
            res: float, shape: tuple[int, int]
            ) -> Iterator[tuple[NDArray[np.bool_], NDArray[np.int64], NDArray[np.int64]]]:
    """(leaf mask, rows, columns) of the pixels under the leaves, one leaf size at a time."""
    rows, cols = shape
    first = np.floor((centers[:, :2] - edge[:, None] / 2 - lo) / res + 1e-9).astype(np.int64)
    span = np.maximum(np.round(edge / res).astype(np.int64), 1)
    for n in np.unique(span):
        sel = span == n
        ii, jj = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
        r = np.clip(first[sel, 1, None] + ii.reshape(1, -1), 0, rows - 1)
        c = np.clip(first[sel, 0, None] + jj.reshape(1, -1), 0, cols - 1)
        yield sel, r, c


def raster(cells: Cells, shift: NDArray[np.float64], max_cells: int = 4_000_000, dims: int = 2,
           rule: OccupancySettings | None = None) -> Raster:
    """Paint the map's leaves onto a grid and classify it (module docstring)."""
    if max_cells < 1:
        raise ParameterError(f"max_cells={max_cells}: expected >= 1")
    known = np.isfinite(cells.centers).all(axis=1)
    if not known.any():
        raise ParameterError("the map has no known cell to rasterise")
    centers, edge = cells.centers[known] + shift, cells.sizes[known, 0]
    lo, res, rows, cols = _footprints(centers, edge, max_cells)
    height = np.full((rows, cols), np.nan)
    seen = np.zeros((rows, cols), dtype=bool)
    occupied = np.asarray(cells.occupied, dtype=bool)[known]
    top = centers[:, 2] + cells.sizes[known, 2] / 2
    values = {name: np.asarray(v, np.float64)[known] for name, v in cells.layers.items()
              } if dims == 2 else {}
    layers = {name: np.full((rows, cols), np.nan) for name in values}
    for sel, r, c in _pixels(centers, edge, lo, res, (rows, cols)):
        seen[r, c] = True
        if dims == 2:
            height[r, c] = centers[sel, 2, None]
            for name, painted in layers.items():
                painted[r, c] = values[name][sel, None]
            continue
        hit = occupied[sel]
        np.fmax.at(height, (r[hit], c[hit]), np.broadcast_to(top[sel][hit, None],
                                                             r[hit].shape))
    surface = classify_surface(height, lo, res, rule)
    occupancy = surface.occupancy()
    occupancy[seen & ~np.isfinite(height)] = 100  # seen, but no surface to rest on
    return Raster(np.array([lo[0], lo[1]]), res, height, occupancy, layers)


def occupancy_grid(grid: Raster, stamp: int, frame: str) -> MsgType:
    """``nav_msgs/msg/OccupancyGrid`` of the raster (row-major from the origin cell)."""
    types = typestore().types
    rows, cols = grid.shape
    info = types["nav_msgs/msg/MapMetaData"](
        time_msg(stamp), float(grid.resolution), cols, rows,
        pose(np.array([grid.origin[0], grid.origin[1], grid.floor]), _IDENTITY))
    return types["nav_msgs/msg/OccupancyGrid"](header(stamp, frame), info,
                                               grid.occupancy.reshape(-1).astype(np.int8))


def _layer(values: NDArray[np.float64]) -> MsgType:
    """A grid_map layer: column-major over grid_map's indices (row = -x, column = -y)."""
    types = typestore().types
    gm = values[::-1, ::-1].T  # [x index from max x, y index from max y]
    rows, cols = gm.shape
    dims = [types["std_msgs/msg/MultiArrayDimension"]("column_index", cols, rows * cols),
            types["std_msgs/msg/MultiArrayDimension"]("row_index", rows, rows)]
    layout = types["std_msgs/msg/MultiArrayLayout"](dims, 0)
    return types["std_msgs/msg/Float32MultiArray"](
        layout, np.asarray(gm, dtype=np.float32).reshape(-1, order="F"))


def grid_map(grid: Raster, stamp: int, frame: str) -> MsgType:
    """``grid_map_msgs/msg/GridMap`` with layers ``elevation`` (m), ``occupancy`` (0-100) and
    the raster's cell layers (e.g. ``variance``, m^2)."""
    rows, cols = grid.shape
    length = np.array([cols, rows], dtype=np.float64) * grid.resolution
    centre = grid.origin + length / 2
    info = blank("grid_map_msgs/msg/GridMapInfo", resolution=float(grid.resolution),
                 length_x=float(length[0]), length_y=float(length[1]),
                 pose=pose(np.array([centre[0], centre[1], 0.0]), _IDENTITY))
    occupancy = np.where(grid.occupancy < 0, np.nan, grid.occupancy.astype(np.float64))
    return blank("grid_map_msgs/msg/GridMap", header=header(stamp, frame), info=info,
                 layers=["elevation", "occupancy", *grid.layers], basic_layers=["elevation"],
                 data=[_layer(grid.height), _layer(occupancy),
                       *(_layer(v) for v in grid.layers.values())])


def grid_fields(grid: Raster) -> tuple[tuple[str, int, int], ...]:
    """The raster's ``foxglove_msgs/msg/Grid`` fields: :data:`GRID_FIELDS`, then one float32
    per cell layer."""
    return GRID_FIELDS + tuple((name, _BASE + 4 * k, _FLOAT32)
                               for k, name in enumerate(grid.layers))


def grid_cells(grid: Raster) -> NDArray[np.void]:
    """The raster as ``foxglove_msgs/msg/Grid`` cells (rows, cols) of :func:`grid_fields`."""
    fields = grid_fields(grid)
    kind = np.dtype({"names": [n for n, _, _ in fields],
                     "formats": [_FORMATS[t] for _, _, t in fields],
                     "offsets": [o for _, o, _ in fields],
                     "itemsize": _BASE + 4 * len(grid.layers)})
    cells = np.zeros(grid.shape, dtype=kind)
    cells["elevation"] = grid.height
    cells["occupancy"] = grid.occupancy
    for name, values in grid.layers.items():
        cells[name] = values
    known = np.isfinite(grid.height)
    rgba = np.rint(height_colours(grid.height[known]) * 255).astype(np.uint8)
    for k, name in enumerate(("red", "green", "blue", "alpha")):
        cells[name][known] = rgba[:, k]
    return cells


def foxglove_grid(grid: Raster, stamp: int, frame: str) -> MsgType:
    """``foxglove_msgs/msg/Grid`` of the raster (row-major from the origin cell)."""
    types = typestore().types
    cols = grid.shape[1]
    fields = [types["foxglove_msgs/msg/PackedElementField"](name, offset, kind)
              for name, offset, kind in grid_fields(grid)]
    cells = grid_cells(grid)
    data = np.frombuffer(cells.tobytes(), dtype=np.uint8)
    corner = np.array([grid.origin[0], grid.origin[1], grid.floor - grid.resolution / 2])
    return types["foxglove_msgs/msg/Grid"](
        time_msg(stamp), frame, pose(corner, _IDENTITY), cols,
        types["foxglove_msgs/msg/Vector2"](float(grid.resolution), float(grid.resolution)),
        cols * cells.dtype.itemsize, cells.dtype.itemsize, fields, data)
