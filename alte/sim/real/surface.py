"""A real terrain's surfaces on one grid, and the labelled mesh the simulated sensor scans.

The grid's cells are ``step`` metres square, on multiples of the step (of a DEM: its
own cells, their centres the grid's nodes). Per cell:

* **bare earth** (``ground``): the mean height of the ground points in the cell (a DEM's
  own value); cells without one are filled by linear interpolation between the cells
  that have one, and by the nearest one beyond them (``measured`` says which are data);
* **object surface** (``top``): where most first returns of the cell are not ground and
  the highest of them stands at least ``min_object`` above the bare earth, that return's
  height and class (a building, a tree, low vegetation, another object); elsewhere the
  bare earth. A canopy with gaps stays porous at the grid's resolution: a cell whose
  first returns mostly reach the ground is ground;
* **coverage** (``covered``): cells within :data:`FILL` metres of a cell holding any
  point. Gaps narrower than twice that are bridged (the ground under a roof, a patch
  without returns); beyond it (outside a survey's footprint, a lake without returns)
  there is no surface: the mesh has a hole there, as the tile has;
* **objects**: the connected cells of one class (8-neighbours) are one object, so the
  obstacle and landing studies have truth. ASPRS 6 is ``building``, 5 ``tree``, 3 and 4
  ``vegetation``, any other class above the ground ``object`` (e.g. vegetation a survey
  left unclassified).

:func:`surface_mesh` triangulates the object surface (two triangles a cell, between cell
centres); a triangle belongs to the object of its highest corner, so the walls between
a roof and the ground are the building's.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy import interpolate, ndimage

from alte.errors import ParameterError
from alte.sim.real.tiles import Tile
from alte.sim.scene import Scene, SceneObject

__all__ = ["CLASS_OF", "FILL", "MIN_OBJECT", "Surfaces", "grid_step", "grid_surfaces",
           "surface_mesh"]

#: ASPRS class -> object class of the ground truth (others above the ground: ``object``).
CLASS_OF = {3: "vegetation", 4: "vegetation", 5: "tree", 6: "building"}
#: Distance (m) from the nearest point within which a cell has a surface.
FILL = 5.0
#: Least height (m) of an object cell above the bare earth: lower ones (grass, kerbs) are
#: ground a vehicle may land on.
MIN_OBJECT = 0.2
_ORDER = ("building", "tree", "vegetation", "object")


@dataclass(eq=False)
class Surfaces:
    """Bare earth, object surface and objects of a terrain on one grid (module docstring);
    ``x0``, ``y0`` are the grid's south-west corner in the tiles' CRS (metres)."""

    x0: float
    y0: float
    step: float
    ground: NDArray[np.float64]
    top: NDArray[np.float64]
    label: NDArray[np.int32]
    objects: tuple[SceneObject, ...]
    measured: NDArray[np.bool_]
    covered: NDArray[np.bool_]

    @property
    def shape(self) -> tuple[int, int]:
        """(rows along y, columns along x)."""
        ny, nx = self.ground.shape
        return ny, nx

    def axes(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Cell-centre coordinates along x and y (CRS metres)."""
        ny, nx = self.shape
        xs = self.x0 + (np.arange(nx, dtype=np.float64) + 0.5) * self.step
        ys = self.y0 + (np.arange(ny, dtype=np.float64) + 0.5) * self.step
        return xs, ys


def grid_step(tiles: list[Tile]) -> float:
    """A DEM's own cell; for points, the cell holding about two first returns (to 0.5 m,
    at least 1 m: the object surface's resolution)."""
    cells = [t.cell for t in tiles if t.cell is not None]
    if cells:
        return float(min(cells))
    pts = np.vstack([t.points[t.first] for t in tiles])
    area = float(np.prod(np.ptp(pts[:, :2], axis=0)))
    density = len(pts) / max(area, 1.0)
    return float(max(1.0, np.ceil(2.0 * np.sqrt(2.0 / density)) / 2.0))


def _index(tiles: list[Tile], step: float) -> tuple[float, float, tuple[int, int]]:
    low = np.min([t.points[:, :2].min(axis=0) for t in tiles], axis=0)
    # A DEM's cell centres are the grid's; points fall in cells on multiples of the step.
    raster = any(t.cell is not None for t in tiles)
    lo = low - 0.5 * step if raster else np.floor(low / step) * step
    hi = np.max([t.points[:, :2].max(axis=0) for t in tiles], axis=0)
    nx, ny = (np.floor((hi - lo) / step).astype(int) + 1).tolist()
    if nx * ny > 25_000_000:
        raise ParameterError(f"a {nx} x {ny} grid of {step:g} m cells is too large; use a "
                             "coarser cell or import fewer tiles", setting="import.cell")
    return float(lo[0]), float(lo[1]), (ny, nx)


def _cells(points: NDArray[np.float64], x0: float, y0: float, step: float,
           shape: tuple[int, int]) -> NDArray[np.intp]:
    col = np.clip(np.floor((points[:, 0] - x0) / step).astype(np.intp), 0, shape[1] - 1)
    row = np.clip(np.floor((points[:, 1] - y0) / step).astype(np.intp), 0, shape[0] - 1)
    flat: NDArray[np.intp] = row * shape[1] + col
    return flat


def _bare_earth(cell: NDArray[np.intp], z: NDArray[np.float64], shape: tuple[int, int]
                ) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    size = shape[0] * shape[1]
    count = np.bincount(cell, minlength=size)
    total = np.bincount(cell, weights=z, minlength=size)
    measured = count > 0
    height = np.full(size, np.nan)
    height[measured] = total[measured] / count[measured]
    if not measured.all():
        grid = measured.reshape(shape)
        # The cells bordering a gap are all a TIN over the gaps needs (far fewer points).
        rim = (grid & ndimage.binary_dilation(~grid, np.ones((3, 3), bool), iterations=2)).ravel()
        rows, cols = np.divmod(np.arange(size), shape[1])
        known = np.column_stack([cols[rim], rows[rim]]).astype(float)
        gaps = np.column_stack([cols[~measured], rows[~measured]]).astype(float)
        filled = (interpolate.griddata(known, height[rim], gaps, method="linear")
                  if rim.sum() >= 3 else np.full(len(gaps), np.nan))
        lost = ~np.isfinite(filled)
        if lost.any():
            filled[lost] = interpolate.griddata(known, height[rim], gaps[lost],
                                                method="nearest")
        height[~measured] = filled
    return height.reshape(shape), measured.reshape(shape)


def _highest_objects(cell: NDArray[np.intp], z: NDArray[np.float64],
                     cls: NDArray[np.uint8], size: int
                     ) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """Per cell the highest object first return's height and ASPRS class (NaN, -1)."""
    top, kind = np.full(size, np.nan), np.full(size, -1, dtype=np.int64)
    if len(cell):
        order = np.lexsort((z, cell))
        last = np.r_[cell[order][1:] != cell[order][:-1], True]
        pick = order[last]
        top[cell[pick]], kind[cell[pick]] = z[pick], cls[pick]
    return top, kind


def _objects(classes: NDArray[np.object_]) -> tuple[NDArray[np.int32], list[SceneObject]]:
    """Connected cells of one class as objects: id per cell (0 = ground) and the objects."""
    label = np.zeros(classes.shape, dtype=np.int32)
    objects = [SceneObject("ground", "ground")]
    for name in _ORDER:
        parts, count = ndimage.label(classes == name, structure=np.ones((3, 3), bool))
        mask = parts > 0
        label[mask] = parts[mask] + len(objects) - 1
        objects += [SceneObject(f"{name}_{k}", name) for k in range(1, count + 1)]
    return label, objects


def grid_surfaces(tiles: list[Tile], step: float | None = None,
                  min_object: float = MIN_OBJECT) -> Surfaces:
    """The :class:`Surfaces` of ``tiles`` (adjacent or overlapping, one CRS) at ``step``
    metres (None: :func:`grid_step`)."""
    step = grid_step(tiles) if step is None else float(step)
    if not (np.isfinite(step) and step > 0):
        raise ParameterError(f"import: cell={step}: expected a positive number of metres",
                             setting="import.cell")
    x0, y0, shape = _index(tiles, step)
    pts = np.vstack([t.points for t in tiles])
    ground = np.concatenate([t.ground for t in tiles])
    first = np.concatenate([t.first for t in tiles])
    classes = np.concatenate([t.classes for t in tiles])
    cell = _cells(pts, x0, y0, step, shape)
    bare, measured = _bare_earth(cell[ground], pts[ground, 2], shape)
    size = shape[0] * shape[1]
    hits = first & ~ground
    votes = (np.bincount(cell[hits], minlength=size)
             > np.bincount(cell[first & ground], minlength=size))
    high, kind = _highest_objects(cell[hits], pts[hits, 2], classes[hits], size)
    is_object = votes & (high >= bare.ravel() + min_object)
    names = np.array([CLASS_OF.get(int(k), "object") for k in kind], dtype=object)
    names[~is_object] = "ground"
    label, objects = _objects(names.reshape(shape))
    top = np.where(is_object, high, bare.ravel()).reshape(shape)
    held = (np.bincount(cell, minlength=size) > 0).reshape(shape)
    reach = int(np.ceil(FILL / step))
    covered = ndimage.binary_dilation(held, np.ones((3, 3), bool), iterations=reach)
    return Surfaces(x0, y0, step, bare, top, label, tuple(objects), measured, covered)


def surface_mesh(surfaces: Surfaces, origin: NDArray[np.float64]) -> Scene:
    """The object surface as a labelled triangle mesh in local coordinates (``origin``
    subtracted), over the covered cells; objects without a triangle of their own are
    left out."""
    ny, nx = surfaces.shape
    xs, ys = surfaces.axes()
    gx, gy = np.meshgrid(xs - origin[0], ys - origin[1])
    vertices = np.column_stack([gx.ravel(), gy.ravel(), surfaces.top.ravel() - origin[2]])
    idx = np.arange(ny * nx).reshape(ny, nx)
    a, b = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel()
    c, d = idx[1:, :-1].ravel(), idx[1:, 1:].ravel()
    triangles = np.vstack([np.column_stack([a, b, d]), np.column_stack([a, d, c])])
    triangles = triangles[surfaces.covered.ravel()[triangles].all(axis=1)]
    corner = np.argmax(vertices[triangles, 2], axis=1)
    owner = surfaces.label.ravel()[triangles[np.arange(len(triangles)), corner]]
    used, ids = np.unique(owner, return_inverse=True)
    objects = tuple(surfaces.objects[i] for i in used)
    return Scene(vertices, triangles.astype(np.int32), ids.astype(np.int32), objects)
