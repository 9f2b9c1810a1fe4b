"""Ground filters: which points of an airborne or drone cloud are bare earth.

:func:`filter_ground` runs one method (:mod:`alte.ground.settings`) on (N, 3) points in
metres and returns a :class:`GroundResult`: the ground mask and, where the method defines
one, the bare-earth height under every point and the height off it a ground point may
have. With those two a caller can ask the same filter about other heights (a map's) at
the same places: :meth:`GroundResult.classify`.

* ``smrf``: the Simple Morphological Filter through ``pysmrf`` (Pingel et al. 2013): the
  minimum raster inpainted, progressively opened with growing disks; cells that rise
  more than slope x step are objects; the rest, inpainted, is the bare earth, and a point
  is ground within ``threshold + scalar x slope`` of it.
* ``csf``: the Cloth Simulation Filter through ``cloth-simulation-filter`` (Zhang et al.
  2016): a cloth dropped on the inverted cloud; ground within ``threshold`` of it. The
  package gives the mask only (no surface).
* ``morph``: alte's baseline, a grey opening of the minimum raster with a square window
  (:func:`opened_surface`) and a constant tolerance.
* ``plane``: the thesis' one MSAC plane.

Input is checked first (:func:`check_cloud`): no points, too few, non-finite values, or a
raster DEM given as points (one point per cell of a regular grid) are typed errors.
"""

from __future__ import annotations

import contextlib
import os
import time
import warnings
from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage

from alte import __version__
from alte.errors import GroundError, ParameterError
from alte.ground.plane import fit_plane_msac, height_above
from alte.ground.settings import (
    DEFAULT_METHOD,
    DEFAULT_SETTINGS,
    SOURCES,
    CsfSettings,
    GroundSettings,
    MorphSettings,
    PlaneSettings,
    SmrfSettings,
    ground_settings,
)
from alte.types import JSONDict, as_points

__all__ = ["GroundResult", "bare_earth_raster", "check_cloud", "classify_ground",
           "filter_ground", "looks_gridded", "opened_surface"]

#: Fewest points a filter accepts (a plane needs 3; a raster filter a few cells).
MIN_POINTS = 3
_MAX_PLANE_POINTS = 50_000


@dataclass(frozen=True, eq=False)
class GroundResult:
    """One filter run: ``ground`` (N,) mask; ``height`` (N,) the bare earth under each
    point and ``tolerance`` (N,) the height off it a ground point may have (None for CSF,
    whose package returns the mask alone); the method, its settings and CPU seconds."""

    ground: NDArray[np.bool_]
    height: NDArray[np.float64] | None
    tolerance: NDArray[np.float64] | None
    method: str
    settings: GroundSettings
    cpu_s: float

    @property
    def share(self) -> float:
        """Share of the points that are ground (0..1)."""
        return float(self.ground.mean()) if len(self.ground) else 0.0

    def classify(self, z: NDArray[np.float64]) -> NDArray[np.bool_]:
        """Other heights ``z`` (N,) at the same places, judged against this run's bare earth
        with its tolerance (NaN -> not ground)."""
        if self.height is None or self.tolerance is None:
            raise ParameterError(f"ground {self.method}: the method gives no bare-earth "
                                 "surface to judge other heights against; use smrf, morph "
                                 "or plane")
        with np.errstate(invalid="ignore"):
            out: NDArray[np.bool_] = np.abs(np.asarray(z) - self.height) <= self.tolerance
        return out

    def provenance(self) -> JSONDict:
        """Which points were called ground and how: software, method, settings and their
        source, point counts (a classified tile's header record, scenario.json's source)."""
        return {"software": f"alte {__version__}", "method": self.method,
                "settings": self.settings.as_dict(), "source": SOURCES[self.method],
                "points": len(self.ground), "ground_points": int(self.ground.sum())}


def looks_gridded(points: NDArray[np.float64]) -> float | None:
    """The spacing (m) when the points' x and y lie on one regular grid, one point per
    node, filling at least half of it: a raster DEM turned into points, not LiDAR
    returns; None otherwise."""
    xy = points[:, :2]
    if len(xy) < 16:
        return None
    ux, uy = np.unique(xy[:, 0]), np.unique(xy[:, 1])
    if len(ux) < 4 or len(uy) < 4 or len(ux) * len(uy) > 2 * len(xy):
        return None
    steps = np.r_[np.diff(ux), np.diff(uy)]
    step = float(steps.min())
    if step <= 0 or not np.allclose(steps / step, np.round(steps / step), atol=1e-3):
        return None
    if len(np.unique(xy, axis=0)) != len(xy):
        return None
    return step


def check_cloud(points: object, owner: str = "ground") -> NDArray[np.float64]:
    """``points`` as (N, 3) float64, refused with a typed error when a ground filter cannot
    use them: too few, non-finite, or a raster DEM given as points."""
    arr = as_points(points, owner=owner, error=ParameterError, finite=True)
    if len(arr) < MIN_POINTS:
        raise GroundError(f"{owner}: {len(arr)} point(s); a ground filter needs at least "
                          f"{MIN_POINTS}")
    step = looks_gridded(arr)
    if step is not None:
        raise GroundError(f"{owner}: the {len(arr)} points lie on a regular {step:g} m grid, "
                          "one point per cell: a raster DEM, not LiDAR returns; a ground "
                          "filter classifies the raw points of a survey")
    return arr


def opened_surface(xy: NDArray[np.float64], heights: NDArray[np.float64], step: float = 1.0,
                   window: float = 20.0) -> NDArray[np.float64]:
    """Per point: the morphological opening (``window`` m square) of the per-pixel
    (``step`` m) minimum of ``heights``; NaN heights are ignored, NaN where none."""
    if not (np.isfinite(step) and step > 0 and np.isfinite(window) and window >= step):
        raise ParameterError(f"ground filter: step={step} must be > 0 and window={window} "
                             ">= step (metres)")
    xy = np.asarray(xy, np.float64)[:, :2]
    if len(xy) == 0:
        return np.empty(0)
    ij = np.floor((xy - xy.min(axis=0)) / step).astype(np.int64)
    grid = np.full(ij.max(axis=0) + 1, np.inf)
    h = np.asarray(heights, np.float64)
    known = np.isfinite(h)
    np.minimum.at(grid, (ij[known, 0], ij[known, 1]), h[known])
    size = (int(np.ceil(window / step)) | 1,) * 2  # odd: centred on the pixel
    low = ndimage.grey_erosion(grid, size=size, mode="nearest")
    opened = ndimage.grey_dilation(np.where(np.isfinite(low), low, -np.inf), size=size,
                                   mode="nearest")
    out = opened[ij[:, 0], ij[:, 1]]
    return np.where(np.isfinite(out), out, np.nan)


def classify_ground(points: NDArray[np.float64], surface: NDArray[np.float64],
                    tolerance: float) -> NDArray[np.bool_]:
    """Ground = within ``tolerance`` metres of ``surface`` (per point; NaN -> not ground)."""
    if not (np.isfinite(tolerance) and tolerance >= 0):
        raise ParameterError(f"ground filter: tolerance={tolerance} must be >= 0 metres")
    with np.errstate(invalid="ignore"):
        ground: NDArray[np.bool_] = np.abs(np.asarray(points)[:, 2] - surface) <= tolerance
    return ground


_Run = tuple[NDArray[np.bool_], NDArray[np.float64] | None, NDArray[np.float64] | None]


def _smrf(pts: NDArray[np.float64], s: SmrfSettings) -> _Run:
    import pysmrf
    from threadpoolctl import threadpool_limits

    radii = max(1, round(s.window / s.cell))
    # pysmrf's spring inpainting (LSQR) is one long run of small BLAS calls: threads only
    # contend there (8x slower on a loaded 2-core machine), so BLAS runs on one thread
    # (rasterio's Affine, inside pysmrf, warns of its own deprecated operator: not ours)
    with threadpool_limits(1, user_api="blas"), warnings.catch_warnings():
        warnings.simplefilter("ignore", PendingDeprecationWarning)
        found = pysmrf.classify(pts[:, 0], pts[:, 1], pts[:, 2], cellsize=s.cell,
                                windows=radii, slope_threshold=s.slope,
                                elevation_threshold=s.threshold, elevation_scaler=s.scalar)
    tolerance = s.threshold + s.scalar * np.asarray(found.slope_values, np.float64)
    return (np.asarray(found.is_ground, bool), np.asarray(found.elevation_values, np.float64),
            tolerance)


@contextlib.contextmanager
def _quiet_stdout() -> Iterator[None]:
    """Silence a compiled library's own prints (CSF writes its progress to file 1)."""
    saved, null = os.dup(1), os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(null, 1)
        yield
    finally:
        os.dup2(saved, 1)
        os.close(saved)
        os.close(null)


def _csf(pts: NDArray[np.float64], s: CsfSettings) -> _Run:
    import CSF

    cloth = CSF.CSF()
    cloth.params.bSloopSmooth = s.slope_smooth
    cloth.params.cloth_resolution = s.resolution
    cloth.params.rigidness = s.rigidness
    cloth.params.class_threshold = s.threshold
    cloth.params.interations = s.iterations
    cloth.params.time_step = s.time_step
    cloth.setPointCloud(np.ascontiguousarray(pts - pts.min(axis=0)))
    ground, objects = CSF.VecInt(), CSF.VecInt()
    with _quiet_stdout():
        cloth.do_filtering(ground, objects, exportCloth=False)
    mask = np.zeros(len(pts), bool)
    mask[np.asarray(ground, dtype=np.int64)] = True
    return mask, None, None


def _morph(pts: NDArray[np.float64], s: MorphSettings) -> _Run:
    if s.window < s.step:
        raise ParameterError(f"ground morph: window={s.window} must be >= step={s.step} (m)")
    height = opened_surface(pts, pts[:, 2], s.step, s.window)
    tolerance = np.full(len(pts), s.tolerance)
    return classify_ground(pts, height, s.tolerance), height, tolerance


def _plane(pts: NDArray[np.float64], s: PlaneSettings) -> _Run:
    fit_on = pts
    if len(pts) > _MAX_PLANE_POINTS:
        pick = np.random.default_rng(s.seed).choice(len(pts), _MAX_PLANE_POINTS, replace=False)
        fit_on = pts[pick]
    plane = fit_plane_msac(fit_on, threshold=s.fit_threshold, seed=s.seed,
                           reference_normal=np.array([0.0, 0.0, 1.0]),
                           max_angle_deg=s.max_angle_deg)
    # the plane's height under each point: z minus the vertical offset to the plane
    height = pts[:, 2] - height_above(pts, plane) / plane.normal[2]
    tolerance = np.full(len(pts), s.tolerance)
    return np.abs(pts[:, 2] - height) <= s.tolerance, height, tolerance


def filter_ground(points: object, method: str | None = None,
                  settings: GroundSettings | None = None) -> GroundResult:
    """Run ``method`` with ``settings`` on (N, 3) points in metres; no method: the ground
    stage's default method and settings, no settings: the method's published defaults.
    The cloud is shifted near the origin first (UTM-safe)."""
    chosen = settings if settings is not None else ground_settings(method)
    method = method or DEFAULT_METHOD
    if not isinstance(chosen, type(ground_settings(method))):
        raise ParameterError(f"ground {method}: settings are {type(chosen).__name__}, not "
                             f"{type(ground_settings(method)).__name__}")
    pts = check_cloud(points, f"ground {method}")
    origin = np.floor(pts.min(axis=0))
    local = pts - origin
    start = time.process_time()
    if isinstance(chosen, SmrfSettings):
        mask, height, tol = _smrf(local, chosen)
    elif isinstance(chosen, CsfSettings):
        mask, height, tol = _csf(local, chosen)
    elif isinstance(chosen, MorphSettings):
        mask, height, tol = _morph(local, chosen)
    else:
        mask, height, tol = _plane(local, chosen)
    cpu = time.process_time() - start
    if height is not None:
        height = height + origin[2]
    return GroundResult(mask, height, tol, method, chosen, cpu)


def bare_earth_raster(height: NDArray[np.float64], step: float, window: float,
                      ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The ground stage's filter (SMRF, :data:`DEFAULT_SETTINGS`) on a height raster: its
    bare earth under every known pixel and the rise its slope allows there (SMRF's
    ``scalar x slope``; NaN elsewhere). The pixel centres are the points (a raster is a
    grid, so the DEM check does not apply); SMRF's cell is the pixel (at least its 1 m)
    and its largest window radius half of ``window``, the side of the widest object."""
    known = np.isfinite(height)
    out, rise = np.full(height.shape, np.nan), np.full(height.shape, np.nan)
    if known.sum() < MIN_POINTS:
        return out, rise
    rows, cols = np.nonzero(known)
    pts = np.column_stack([cols * step, rows * step, height[known]])
    base = DEFAULT_SETTINGS if isinstance(DEFAULT_SETTINGS, SmrfSettings) else SmrfSettings()
    chosen = base.replace(cell=max(step, base.cell), window=max(window / 2, step))
    origin = np.array([0.0, 0.0, float(np.floor(pts[:, 2].min()))])
    _, bare, tolerance = _smrf(pts - origin, chosen)
    assert bare is not None and tolerance is not None  # SMRF always gives both
    out[known] = bare + origin[2]
    rise[known] = tolerance - chosen.threshold
    return out, rise
