"""Landing-zone parameters: the vehicle, its safety margins and the terrain limits.

A landing site (thesis 1.2: "any planar site, free of obstacles, with a clear approach
path, and with an area big enough for the vehicle to land") is tested at a candidate
centre on a raster of the 2D map:

* the disk of radius ``radius + margin`` (footprint plus position margin) is known,
  has a least-squares plane tilted at most ``max_slope_deg`` and residuals with a
  standard deviation of at most ``max_roughness`` (m);
* no obstacle lies closer than ``radius + clearance`` to the centre (and none inside
  the disk), an obstacle being a raster pixel more than ``obstacle_height`` above or
  below the ground plane;
* with ``max_height_sigma`` set (a map whose cells carry a height variance, e.g. the
  elevation map), every pixel of the disk is known to within that standard deviation: a
  pixel the map is less sure of counts as unknown, so a flat patch the map has barely
  seen is not a site. :data:`SIGMA_OF_OBSTACLE` is the bound the landing study tries.

Defaults fit the thesis' quadrotor over the simulated urban-scale terrains; the
experimental terrains live in an 8 m x 6 m lab, where the same vehicle would not fit
between the debris, so :func:`landing_params` scales everything down for them
(:data:`LAB`: a 0.25 m radius vehicle and 5 cm raster).
"""

from __future__ import annotations

from dataclasses import dataclass

from alte.errors import ParameterError
from alte.ground.surface import OccupancySettings
from alte.params import Record, param

__all__ = ["LAB", "QUADROTOR", "SIGMA_OF_OBSTACLE", "LandingSettings", "landing_params"]

#: The height sigma bound the landing study tries, as a share of the obstacle height:
#: 2 sigma of a quarter of the step that makes an obstacle leaves a known pixel's height
#: within half that step, so no obstacle hides in the map's uncertainty.
SIGMA_OF_OBSTACLE = 0.25


@dataclass(frozen=True)
class LandingSettings(Record):
    """What makes a safe landing site (module docstring); validated on creation."""

    OWNER = "landing"

    radius: float = param(1.0, lambda v: v > 0, "radius > 0",
                          "vehicle footprint radius (m), rotors included")
    margin: float = param(0.5, lambda v: v >= 0, "margin >= 0",
                          "added to the radius for position error (m)")
    clearance: float = param(1.0, lambda v: v >= 0, "clearance >= 0",
                             "free gap between the footprint and the nearest obstacle (m)")
    max_slope_deg: float = param(10.0, lambda v: 0 < v < 90, "0 < max_slope_deg < 90",
                                 "steepest plane a skid can rest on (degrees)")
    max_roughness: float = param(0.1, lambda v: v > 0, "max_roughness > 0",
                                 "largest plane-fit residual std inside the disk (m)")
    obstacle_height: float = param(0.3, lambda v: v > 0, "obstacle_height > 0",
                                   "height step that makes a pixel an obstacle (m)")
    step: float = param(0.25, lambda v: v > 0, "0 < step <= radius", "raster pixel (m)")
    max_sites: int = param(5, lambda v: v >= 1, "max_sites >= 1",
                           "best ranked sites chosen and scored")
    max_height_sigma: float | None = param(
        None, lambda v: v > 0, "max_height_sigma > 0",
        "largest height standard deviation of a pixel a site may hold (m; None: no bound; "
        "needs a map with a height variance)")

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.step > self.radius:
            raise ParameterError(f"{self.OWNER}: step={self.step!r} out of range "
                                 "(0 < step <= radius)")

    @property
    def disk(self) -> float:
        """Radius (m) of the disk that must be known, planar and obstacle-free."""
        return self.radius + self.margin

    @property
    def surface(self) -> OccupancySettings:
        """The landing criterion of :mod:`alte.ground.surface` these limits give (window:
        the disk; ground: the MSAC plane)."""
        return OccupancySettings(window=self.disk, max_slope_deg=self.max_slope_deg,
                           max_roughness=self.max_roughness,
                           obstacle_height=self.obstacle_height, ground="plane")

    @property
    def keep_out(self) -> float:
        """Smallest distance (m) from a site centre to an obstacle."""
        return max(self.radius + self.clearance, self.disk)


#: The thesis' quadrotor over the simulated terrains (the defaults).
QUADROTOR = LandingSettings()
#: A vehicle scaled to the 8 m x 6 m lab of the experimental terrains (thesis 2.2.4).
LAB = LandingSettings(radius=0.25, margin=0.1, clearance=0.15, max_slope_deg=10.0,
                    max_roughness=0.03, obstacle_height=0.06, step=0.05)


def landing_params(terrain: str, **overrides: object) -> LandingSettings:
    """The preset for ``terrain`` (``exp_*``: :data:`LAB`, else :data:`QUADROTOR`), overridden."""
    base = LAB if terrain.startswith("exp_") else QUADROTOR
    return base.replace(**overrides)
