"""The obstacles a landing UAV must see, from the simulator's mesh, on a raster.

A *true obstacle* is one simulator object (its object id), of a class other than
``ground``, whose top stands at least ``min_height`` above the ground and which can be
seen from above: some pixel of its x/y footprint (the convex hull of its vertices,
:func:`~alte.lab.studies.landing.object_footprints`) has that object as its top surface
(a vertical ray cast down the mesh through the pixel centre), or has the ground there
while no taller object's footprint covers the pixel (an object thinner than a pixel,
a fence post, which the ray through the centre misses). An object wholly under
another one (a house under its roof, a trunk under its crown, bridge pillars under
the deck) is *hidden*: no top-down map can show it, and the object above it is the
obstacle. The ground is the median top height of the pixels whose top surface is
ground.

``min_height`` defaults to the landing study's obstacle step for the terrain
(:attr:`~alte.lab.studies.landing.LandingSettings.obstacle_height`: 0.3 m for the
thesis-scale quadrotor, about its landing-gear clearance, so a taller object under
its frame strikes it; 0.06 m for the lab-scale vehicle), and the raster to the
landing study's pixel (0.25 m, 0.05 m), so both studies call the same things
obstacles.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage

from alte.errors import MetricsError
from alte.lab.studies.landing import (
    GROUND_CLASSES,
    RasterGeometry,
    landing_params,
    object_footprints,
    top_surface,
)
from alte.metrics import TrueSurface
from alte.params import Record, param
from alte.types import Box

__all__ = ["ObstacleSettings", "TrueObstacles", "obstacle_options", "terrain_obstacles",
           "true_obstacles"]


@dataclass(frozen=True)
class ObstacleSettings(Record):
    """How obstacles are told and matched (see the module docstring)."""

    OWNER: ClassVar[str] = "obstacles"
    min_height: float = param(0.3, lambda v: v > 0, "min_height > 0",
                              "height above the ground (m) from which an object is an obstacle")
    step: float = param(0.25, lambda v: v > 0, "step > 0", "raster pixel (m)")
    slack: int = param(1, lambda v: v >= 0, "slack >= 0",
                       "pixels a map obstacle may lie off a true footprint and still match it")


def obstacle_options(terrain: str) -> ObstacleSettings:
    """The options for ``terrain``: the landing study's obstacle step and pixel."""
    landing = landing_params(terrain)
    return ObstacleSettings(min_height=landing.obstacle_height, step=landing.step)


@dataclass(frozen=True, eq=False)
class TrueObstacles:
    """The true obstacles of one terrain on ``grid`` (flat pixel indices, row-major).

    Per visible obstacle: ``ids`` (simulator object id), ``names``, ``classes``,
    ``heights`` (top above the ground, m), ``footprints`` (its visible pixels) and
    ``near`` (those pixels grown by ``options.slack``). ``objects``: every pixel of any
    non-ground object's footprint, grown the same way (where a map obstacle is real);
    ``hidden``: names of the objects tall enough but covered from above.
    """

    grid: RasterGeometry
    options: ObstacleSettings
    ground: float
    ids: NDArray[np.int64]
    names: tuple[str, ...]
    classes: tuple[str, ...]
    heights: NDArray[np.float64]
    footprints: tuple[NDArray[np.intp], ...]
    near: tuple[NDArray[np.intp], ...]
    objects: NDArray[np.bool_]
    hidden: tuple[str, ...]

    def __len__(self) -> int:
        return len(self.ids)


def _grow(mask: NDArray[np.bool_], pixels: int) -> NDArray[np.bool_]:
    if pixels <= 0 or not mask.any():
        return mask
    grown: NDArray[np.bool_] = ndimage.binary_dilation(mask, np.ones((3, 3), bool),
                                                       iterations=pixels)
    return grown


def _ground_level(height: NDArray[np.float64], top_ids: NDArray[np.int64],
                  ground_ids: NDArray[np.int64]) -> float:
    on_ground = np.isin(top_ids, ground_ids) & np.isfinite(height)
    if not on_ground.any():
        raise MetricsError("obstacle truth: no pixel sees the ground, so heights have no datum")
    return float(np.median(height[on_ground]))


def _object_tops(surface: TrueSurface, ids: NDArray[np.int64]) -> NDArray[np.float64]:
    return np.array([surface.vertices[surface.triangles[surface.object_ids == i].ravel(), 2].max()
                     for i in ids], dtype=np.float64)


def true_obstacles(surface: TrueSurface, bounds: Box, options: ObstacleSettings) -> TrueObstacles:
    """The true obstacles of ``surface`` inside the control volume ``bounds``."""
    if not surface.classes:
        raise MetricsError("obstacle truth: the true surface has no object classes, so the "
                           "ground cannot be told from obstacles")
    box = bounds.array()
    grid = RasterGeometry.from_bounds(box, options.step)
    height, top_ids = top_surface(surface, grid.centers(), float(box[1, 2]))
    ground_ids = np.array([i for i, c in surface.classes.items() if c in GROUND_CLASSES])
    ground = _ground_level(height, top_ids, ground_ids)
    others = np.array(sorted(i for i, c in surface.classes.items() if c not in GROUND_CLASSES))
    tops = _object_tops(surface, others) - ground if len(others) else np.zeros(0)
    top_ids = top_ids.reshape(grid.shape)
    hulls = [object_footprints(surface, grid, np.array([oid])) for oid in others]
    cover = np.full(grid.shape, -np.inf)  # the tallest object whose footprint holds a pixel
    for hull, top in zip(hulls, tops, strict=True):
        cover[hull] = np.maximum(cover[hull], top)
    on_ground = np.isin(top_ids, ground_ids)
    kept: list[tuple[int, NDArray[np.intp], NDArray[np.intp], float]] = []
    hidden = []
    for oid, hull, top in zip(others, hulls, tops, strict=True):
        if top < options.min_height or not hull.any():
            continue
        visible = hull & ((top_ids == oid) | (on_ground & (cover <= top)))
        if not visible.any():
            hidden.append(surface.labels.get(int(oid), f"object_{oid}"))
            continue
        kept.append((int(oid), np.flatnonzero(visible),
                     np.flatnonzero(_grow(visible, options.slack)), float(top)))
    objects = np.any(hulls, axis=0) if hulls else np.zeros(grid.shape, dtype=bool)
    return TrueObstacles(
        grid, options, ground, np.array([k[0] for k in kept], dtype=np.int64),
        tuple(surface.labels.get(k[0], f"object_{k[0]}") for k in kept),
        tuple(surface.classes[k[0]] for k in kept), np.array([k[3] for k in kept]),
        tuple(k[1] for k in kept), tuple(k[2] for k in kept),
        _grow(objects, options.slack).ravel(), tuple(hidden))


@functools.lru_cache(maxsize=4)
def _cached(folder: str, options: ObstacleSettings) -> TrueObstacles:
    from alte.pipeline import open_input

    truth = open_input(folder).ground_truth()
    if truth is None:
        raise MetricsError(f"obstacle truth: {folder} is not a simulated terrain")
    return true_obstacles(truth.surface, truth.bounds, options)


def terrain_obstacles(folder: str, options: ObstacleSettings) -> TrueObstacles:
    """:func:`true_obstacles` of the simulated terrain in ``folder`` (once per process)."""
    return _cached(str(folder), options)
