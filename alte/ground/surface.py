"""Where a vehicle can rest on a height raster: the landing surface criterion.

A known pixel of a height raster (NaN = unknown) is **landable** when

* the least-squares plane ``z = a x + b y + c`` over the square window of half-side
  ``window`` (m, at least one pixel) around it is tilted at most ``max_slope_deg``
  and its residuals have a standard deviation of at most ``max_roughness`` (m);
* it is no obstacle: at most ``obstacle_height`` (m) above or below the ground. The
  ground is the MSAC plane of the known pixels (``ground=plane``, thesis 2.1.4: one
  plane for the whole map) or the raster's grey opening over a square of side
  ``ground_window`` (``ground=local``: the lowest surface that objects narrower than
  the window stand on, as in the morphological ground filters of airborne LiDAR; it
  follows hills that a single plane cannot). An opening also shaves the top of a
  convex slope (a crest, a hill top, a ramp at the map's edge) by up to the grade
  times half the window, so the allowance grows by ``g * ground_window / 2``, with
  ``g`` the mean grade (tangent of the window-plane slope, each capped at
  ``max_slope_deg``) over the ground window: the slope tolerance of the progressive
  morphological filter (Zhang et al. 2003), measured around each pixel. On flat ground
  a roof or a box keeps nearly the bare ``obstacle_height``; only the ring its own
  edges tilt adds to it. ``ground=filter`` takes the bare earth of the ground stage's
  filter run on the raster (SMRF, :func:`alte.ground.filters.bare_earth_raster`), the
  allowance SMRF's own: its scaling factor times the bare earth's slope.

:func:`classify_surface` applies it to every pixel at once (image filters, one
vectorised pass); the landing study (:mod:`alte.lab.studies.landing`) tests site centres
with the same functions, and the MCAP export paints its occupancy grids with it.
:func:`plane_features` fits the window planes with ten ``uniform_filter`` passes over
the moments ``1, x, y, z, x^2, xy, y^2, xz, yz, z^2`` of the known pixels.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage

from alte.ground.plane import fit_plane_msac
from alte.params import Record, param

__all__ = [
    "OccupancySettings",
    "PlaneFeatures",
    "Surface",
    "classify_surface",
    "ground_obstacles",
    "local_ground",
    "pixel_centres",
    "planar",
    "plane_features",
]

_MAX_FIT_PIXELS = 50_000


@dataclass(frozen=True)
class OccupancySettings(Record):
    """The landing criterion's thresholds (module docstring); validated on creation.

    Defaults are the landing study's quadrotor (:data:`alte.lab.studies.landing.QUADROTOR`:
    a 1 m footprint radius plus 0.5 m margin as the plane window).
    """

    OWNER = "occupancy"

    window: float = param(1.5, lambda v: v > 0, "window > 0",
                          "half-side of the square the local plane is fitted over (m)")
    max_slope_deg: float = param(10.0, lambda v: 0 < v < 90, "0 < max_slope_deg < 90",
                                 "steepest local plane a vehicle can rest on (degrees)")
    max_roughness: float = param(0.1, lambda v: v > 0, "max_roughness > 0",
                                 "largest residual std about the local plane (m)")
    obstacle_height: float = param(0.3, lambda v: v > 0, "obstacle_height > 0",
                                   "height above the ground (or below a plane ground) "
                                   "that makes an obstacle (m)")
    ground: Literal["plane", "local", "filter"] = param(
        "local", rule="plane|local|filter",
        help="ground reference: one MSAC plane, the local grey opening, or the ground "
             "stage's filter (SMRF) bare earth")
    ground_window: float = param(20.0, lambda v: v > 0, "ground_window > 0",
                                 "side of the local ground's opening square (m): wider than "
                                 "the widest object to flag")


@dataclass(frozen=True)
class PlaneFeatures:
    """Per pixel: plane tilt ``slope_deg``, residual std ``roughness`` (m), known ``count``.

    NaN where the window's known pixels do not fix a plane (fewer than 3, collinear).
    """

    slope_deg: NDArray[np.float64]
    roughness: NDArray[np.float64]
    count: NDArray[np.int64]


@dataclass(frozen=True)
class Surface:
    """Per pixel of a raster: ``free`` (landable), ``occupied`` (known, not landable) and
    the tests behind them (``slope_deg``, ``roughness``, ``obstacle``)."""

    free: NDArray[np.bool_]
    occupied: NDArray[np.bool_]
    slope_deg: NDArray[np.float64]
    roughness: NDArray[np.float64]
    obstacle: NDArray[np.bool_]

    def occupancy(self) -> NDArray[np.int8]:
        """``nav_msgs/OccupancyGrid`` values: 0 free, 100 occupied, -1 unknown (int8)."""
        out = np.full(self.free.shape, -1, dtype=np.int8)
        out[self.free] = 0
        out[self.occupied] = 100
        return out


def plane_features(height: NDArray[np.float64], step: float, radius: float) -> PlaneFeatures:
    """Least-squares plane over the square window of half-side ``radius`` (m) at every pixel."""
    known = np.isfinite(height)
    half = max(int(np.ceil(radius / step - 1e-9)), 1)
    size = 2 * half + 1
    ny, nx = height.shape
    y, x = np.meshgrid((np.arange(ny) - ny / 2) * step, (np.arange(nx) - nx / 2) * step,
                       indexing="ij")
    w = known.astype(np.float64)
    z = np.where(known, height - np.median(height[known]), 0.0) if known.any() else w

    def mean(values: NDArray[np.float64]) -> NDArray[np.float64]:
        return ndimage.uniform_filter(values * w, size=size, mode="constant", cval=0.0)

    s1 = mean(np.ones_like(z))
    with np.errstate(invalid="ignore", divide="ignore"):
        mx, my, mz = mean(x) / s1, mean(y) / s1, mean(z) / s1
        cxx = mean(x * x) / s1 - mx * mx
        cyy = mean(y * y) / s1 - my * my
        cxy = mean(x * y) / s1 - mx * my
        cxz = mean(x * z) / s1 - mx * mz
        cyz = mean(y * z) / s1 - my * mz
        czz = mean(z * z) / s1 - mz * mz
        det = cxx * cyy - cxy * cxy
        ok = (s1 * size * size >= 2.5) & (det > 1e-6 * step**4)
        a = np.where(ok, (cyy * cxz - cxy * cyz) / det, np.nan)
        b = np.where(ok, (cxx * cyz - cxy * cxz) / det, np.nan)
        residual = np.maximum(czz - a * cxz - b * cyz, 0.0)
    slope = np.degrees(np.arctan(np.hypot(a, b)))
    return PlaneFeatures(slope, np.sqrt(residual), np.rint(s1 * size * size).astype(np.int64))


def planar(feats: PlaneFeatures, rule: OccupancySettings) -> NDArray[np.bool_]:
    """Pixels whose window plane is within the slope and roughness limits (NaN: not)."""
    with np.errstate(invalid="ignore"):
        flat: NDArray[np.bool_] = (feats.slope_deg <= rule.max_slope_deg) & \
                           (feats.roughness <= rule.max_roughness)
    return flat


def pixel_centres(origin: tuple[float, float] | NDArray[np.float64], step: float,
                  shape: tuple[int, int]) -> NDArray[np.float64]:
    """Pixel centres (ny * nx, 2), row-major (y slow, x fast), of a raster whose lower-left
    corner is ``origin``."""
    ny, nx = shape
    xs = origin[0] + (np.arange(nx) + 0.5) * step
    ys = origin[1] + (np.arange(ny) + 0.5) * step
    gx, gy = np.meshgrid(xs, ys, indexing="xy")
    return np.column_stack([gx.ravel(), gy.ravel()])


def ground_obstacles(height: NDArray[np.float64], centres: NDArray[np.float64],
                     obstacle_height: float, ground: float | None = None, seed: int = 0,
                     ) -> NDArray[np.bool_]:
    """Known pixels more than ``obstacle_height`` above or below the ground plane.

    ``centres`` are the pixel centres (:func:`pixel_centres`); ``ground`` is a height (m),
    None fits the ground plane with MSAC (thesis 2.1.4) to the known pixels (at most
    50 000 of them, drawn with a seeded generator).
    """
    known: NDArray[np.bool_] = np.isfinite(height)
    if ground is not None:
        return known & (np.abs(np.where(known, height, ground) - ground) > obstacle_height)
    if known.sum() < 3:
        return np.zeros(height.shape, dtype=bool)
    pts = np.column_stack([centres[known.ravel()], height[known]])
    if len(pts) > _MAX_FIT_PIXELS:
        pts = pts[np.random.default_rng(seed).choice(len(pts), _MAX_FIT_PIXELS, replace=False)]
    plane = fit_plane_msac(pts, threshold=obstacle_height / 2, seed=seed,
                           reference_normal=np.array([0.0, 0.0, 1.0]), max_angle_deg=30.0)
    above = centres @ plane.normal[:2] + height.ravel() * plane.normal[2] + plane.d
    obstacles: NDArray[np.bool_] = known & (np.abs(np.nan_to_num(above.reshape(height.shape)))
                                     > obstacle_height)
    return obstacles


def local_ground(height: NDArray[np.float64], step: float, window: float,
                 ) -> NDArray[np.float64]:
    """Grey opening of the known heights over a square of side ``window`` (m, odd pixel
    count, at least 3); unknown pixels and the outside of the raster take no part; NaN
    where no known pixel is near."""
    size = max(2 * round(window / step / 2) + 1, 3)
    known = np.isfinite(height)
    low = ndimage.minimum_filter(np.where(known, height, np.inf), size=size, mode="constant",
                                 cval=np.inf)
    low = np.where(np.isfinite(low), low, -np.inf)
    ground = ndimage.maximum_filter(low, size=size, mode="constant", cval=-np.inf)
    return np.where(np.isfinite(ground), ground, np.nan)


def _obstacles(height: NDArray[np.float64], origin: tuple[float, float] | NDArray[np.float64],
               step: float, rule: OccupancySettings, slope_deg: NDArray[np.float64], *, seed: int,
               ) -> NDArray[np.bool_]:
    """Obstacle pixels: off the MSAC plane, or above the local ground by more than
    ``obstacle_height`` plus the rise the terrain's slope explains over half the ground
    window (module docstring)."""
    if rule.ground == "plane":
        return ground_obstacles(height, pixel_centres(origin, step, height.shape),
                                rule.obstacle_height, seed=seed)
    if rule.ground == "filter":
        from alte.ground.filters import bare_earth_raster

        bare, rise = bare_earth_raster(height, step, rule.ground_window)
        with np.errstate(invalid="ignore"):
            above: NDArray[np.bool_] = np.isfinite(height) & (
                np.nan_to_num(height - bare) > rule.obstacle_height + np.nan_to_num(rise))
        return above
    ground = local_ground(height, step, rule.ground_window)
    known = np.isfinite(height) & np.isfinite(slope_deg)
    grade = np.tan(np.radians(np.minimum(np.where(known, slope_deg, 0.0), rule.max_slope_deg)))
    size = max(2 * round(rule.ground_window / step / 2) + 1, 3)
    weight = ndimage.uniform_filter(known.astype(np.float64), size=size, mode="constant")
    with np.errstate(invalid="ignore", divide="ignore"):
        mean_grade = np.where(weight > 1e-6, ndimage.uniform_filter(
            grade, size=size, mode="constant") / weight, 0.0)
        allowed = rule.obstacle_height + mean_grade * rule.ground_window / 2
        step_up: NDArray[np.bool_] = np.isfinite(height) & (
            np.nan_to_num(height - ground) > allowed)
    return step_up


def classify_surface(height: NDArray[np.float64],
                     origin: tuple[float, float] | NDArray[np.float64],
                     step: float, rule: OccupancySettings | None = None, seed: int = 0) -> Surface:
    """Free / occupied / unknown for every pixel of a height raster (module docstring).

    A known pixel whose window does not fix a plane (an isolated cell) is occupied: a
    vehicle cannot tell how it would rest there.
    """
    rule = rule or OccupancySettings()
    height = np.asarray(height, dtype=np.float64)
    known = np.isfinite(height)
    feats = plane_features(height, step, rule.window)
    obstacle = _obstacles(height, origin, step, rule, feats.slope_deg, seed=seed) & known
    free = known & planar(feats, rule) & ~obstacle
    return Surface(free, known & ~free, feats.slope_deg, feats.roughness, obstacle)
