"""Map messages: cube lists coloured by height, 2D grids (occupancy + height), Octomap.

* :func:`cell_markers`: ``visualization_msgs/msg/MarkerArray``, one ``CUBE_LIST`` per
  cell size (a cube list has one scale), each cube coloured by its height (viridis
  over the shown cells' height range); a ``DELETEALL`` marker first, so a timeline
  update replaces the previous map. 2D cells (no thickness) are drawn as tiles.
* :func:`raster`: a 2D map's leaves painted onto a regular grid at the finest leaf
  size (coarsened by powers of two to at most ``max_cells``), then
  :func:`occupancy_grid` (``nav_msgs/msg/OccupancyGrid``: 100 occupied, 0 free,
  -1 unknown) and :func:`grid_map` (``grid_map_msgs/msg/GridMap``, layers
  ``elevation`` and ``occupancy``, NaN where unknown).
* :func:`octomap_msg`: the Octomap mapper's maximum-likelihood binary tree, the
  payload of its ``.bt`` file, as ``octomap_msgs/msg/Octomap`` (binary, id ``OcTree``).
"""

from __future__ import annotations

import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from alte.errors import ParameterError
from alte.export.rosmsg import blank, header, pose, typestore
from alte.mappers import Cells, Octomap

__all__ = ["CUBE_LIST", "DELETEALL", "Raster", "cell_markers", "grid_map", "height_colours",
           "occupancy_grid", "octomap_msg", "raster", "shown_cells"]

CUBE_LIST, ADD, DELETEALL = 6, 0, 3
#: Thickness of a 2D cell's tile, as a fraction of its edge.
TILE = 0.05
_BT_DATA = b"\ndata\n"


def shown_cells(cells: Cells, dims: int, everything: bool = False) -> np.ndarray:
    """Mask of the cells drawn: occupied (3D maps) or known (2D height maps: a free leaf is
    ground at its height); ``everything`` adds the free cells of a 3D map."""
    known: np.ndarray = np.isfinite(cells.centers).all(axis=1)
    if dims == 2 or everything:
        return known
    shown: np.ndarray = known & np.asarray(cells.occupied, dtype=bool)
    return shown


def height_colours(z: np.ndarray) -> np.ndarray:
    """(N, 4) RGBA in 0..1, viridis over the heights' range (one colour when flat)."""
    from matplotlib import colormaps

    if not len(z):
        return np.empty((0, 4))
    lo, hi = float(np.min(z)), float(np.max(z))
    t = (z - lo) / (hi - lo) if hi > lo else np.full(len(z), 0.5)
    return np.asarray(colormaps["viridis"](t), dtype=np.float64)


def _cube_list(head: Any, ident: int, size: np.ndarray, centers: np.ndarray,
               colours: np.ndarray) -> Any:
    types = typestore().types
    point, rgba = types["geometry_msgs/msg/Point"], types["std_msgs/msg/ColorRGBA"]
    return blank("visualization_msgs/msg/Marker", header=head, ns="cells",
                 id=ident, type=CUBE_LIST, action=ADD,
                 pose=pose(np.zeros(3), np.array([0.0, 0.0, 0.0, 1.0])),
                 scale=types["geometry_msgs/msg/Vector3"](*map(float, size)),
                 color=rgba(1.0, 1.0, 1.0, 1.0),
                 points=[point(*map(float, c)) for c in centers],
                 colors=[rgba(*map(float, c)) for c in colours])


def cell_markers(cells: Cells, mask: np.ndarray, stamp: int, frame: str,
                 shift: np.ndarray) -> Any:
    """MarkerArray of the masked cells (centres moved back by the local ``shift``)."""
    centers = cells.centers[mask] + shift
    sizes = cells.sizes[mask].copy()
    flat = sizes[:, 2] == 0
    sizes[flat, 2] = TILE * sizes[flat, 0]
    colours = height_colours(centers[:, 2])
    groups, which = np.unique(sizes, axis=0, return_inverse=True)
    markers = [blank("visualization_msgs/msg/Marker", header=header(stamp, frame), ns="cells",
                     action=DELETEALL)]
    for g, size in enumerate(groups):
        sel = which.reshape(-1) == g
        markers.append(_cube_list(header(stamp, frame), g, size, centers[sel], colours[sel]))
    return typestore().types["visualization_msgs/msg/MarkerArray"](markers)


@dataclass(frozen=True)
class Raster:
    """A 2D map on a regular grid: row ``i`` is y, column ``j`` is x, cell (0, 0) has its
    lower-left corner at ``origin``; NaN height and -1 occupancy where unknown."""

    origin: np.ndarray
    resolution: float
    height: np.ndarray
    occupancy: np.ndarray

    @property
    def shape(self) -> tuple[int, int]:
        """(rows = cells along y, columns = cells along x)."""
        return (int(self.height.shape[0]), int(self.height.shape[1]))


def raster(cells: Cells, shift: np.ndarray, max_cells: int = 4_000_000) -> Raster:
    """Paint the known 2D leaves onto a grid at the finest leaf size (coarser when needed)."""
    if max_cells < 1:
        raise ParameterError(f"max_cells={max_cells}: expected >= 1")
    known = np.isfinite(cells.centers[:, 2])
    if not known.any():
        raise ParameterError("the map has no known cell to rasterise")
    centers, edge = cells.centers[known] + shift, cells.sizes[known, 0]
    lo = (centers[:, :2] - edge[:, None] / 2).min(axis=0)
    hi = (centers[:, :2] + edge[:, None] / 2).max(axis=0)
    res = float(edge.min())
    while np.prod(np.ceil((hi - lo) / res - 1e-9)) > max_cells:
        res *= 2
    cols, rows = (int(v) for v in np.maximum(np.ceil((hi - lo) / res - 1e-9), 1))
    height = np.full((rows, cols), np.nan)
    occupancy = np.full((rows, cols), -1, dtype=np.int8)
    first = np.floor((centers[:, :2] - edge[:, None] / 2 - lo) / res + 1e-9).astype(np.int64)
    span = np.maximum(np.round(edge / res).astype(np.int64), 1)
    occ = np.where(cells.occupied[known], 100, 0).astype(np.int8)
    for n in np.unique(span):
        sel = span == n
        ii, jj = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
        r = np.clip(first[sel, 1, None] + ii.reshape(1, -1), 0, rows - 1)
        c = np.clip(first[sel, 0, None] + jj.reshape(1, -1), 0, cols - 1)
        height[r, c] = centers[sel, 2, None]
        occupancy[r, c] = occ[sel, None]
    return Raster(np.array([lo[0], lo[1]]), res, height, occupancy)


def occupancy_grid(grid: Raster, stamp: int, frame: str) -> Any:
    """``nav_msgs/msg/OccupancyGrid`` of the raster (row-major from the origin cell)."""
    types = typestore().types
    rows, cols = grid.shape
    info = types["nav_msgs/msg/MapMetaData"](
        header(stamp, frame).stamp, float(grid.resolution), cols, rows,
        pose(np.array([grid.origin[0], grid.origin[1], 0.0]), np.array([0.0, 0.0, 0.0, 1.0])))
    return types["nav_msgs/msg/OccupancyGrid"](header(stamp, frame), info,
                                               grid.occupancy.reshape(-1).astype(np.int8))


def _layer(values: np.ndarray) -> Any:
    """A grid_map layer: column-major over grid_map's indices (row = -x, column = -y)."""
    types = typestore().types
    gm = values[::-1, ::-1].T  # [x index from max x, y index from max y]
    rows, cols = gm.shape
    dims = [types["std_msgs/msg/MultiArrayDimension"]("column_index", cols, rows * cols),
            types["std_msgs/msg/MultiArrayDimension"]("row_index", rows, rows)]
    layout = types["std_msgs/msg/MultiArrayLayout"](dims, 0)
    return types["std_msgs/msg/Float32MultiArray"](
        layout, np.asarray(gm, dtype=np.float32).reshape(-1, order="F"))


def grid_map(grid: Raster, stamp: int, frame: str) -> Any:
    """``grid_map_msgs/msg/GridMap`` with layers ``elevation`` (m) and ``occupancy`` (0-100)."""
    rows, cols = grid.shape
    length = np.array([cols, rows], dtype=np.float64) * grid.resolution
    centre = grid.origin + length / 2
    info = blank("grid_map_msgs/msg/GridMapInfo", resolution=float(grid.resolution),
                 length_x=float(length[0]), length_y=float(length[1]),
                 pose=pose(np.array([centre[0], centre[1], 0.0]), np.array([0.0, 0.0, 0.0, 1.0])))
    occupancy = np.where(grid.occupancy < 0, np.nan, grid.occupancy.astype(np.float64))
    return blank("grid_map_msgs/msg/GridMap", header=header(stamp, frame), info=info,
                 layers=["elevation", "occupancy"], basic_layers=["elevation"],
                 data=[_layer(grid.height), _layer(occupancy)])


def octomap_msg(mapper: Octomap, stamp: int, frame: str) -> Any:
    """The binary tree of ``mapper`` (its ``.bt`` payload) as ``octomap_msgs/msg/Octomap``."""
    with tempfile.TemporaryDirectory() as tmp:
        path = mapper.write_bt(Path(tmp) / "map.bt")
        content = path.read_bytes()
    start = content.index(_BT_DATA) + len(_BT_DATA)
    data = np.frombuffer(content[start:], dtype=np.int8).copy()
    return blank("octomap_msgs/msg/Octomap", header=header(stamp, frame), binary=True,
                 id="OcTree", resolution=float(mapper.voxel_size), data=data)
