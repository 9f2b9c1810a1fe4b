"""Landing-zone parameters: the vehicle, its safety margins and the terrain limits.

A landing site (thesis 1.2: "any planar site, free of obstacles, with a clear approach
path, and with an area big enough for the vehicle to land") is tested at a candidate
centre on a raster of the 2D map:

* the disk of radius ``radius + margin`` (footprint plus position margin) is known,
  has a least-squares plane tilted at most ``max_slope_deg`` and residuals with a
  standard deviation of at most ``max_roughness`` (m);
* no obstacle lies closer than ``radius + clearance`` to the centre (and none inside
  the disk), an obstacle being a raster pixel more than ``obstacle_height`` above or
  below the ground plane.

Defaults fit the thesis' quadrotor over the simulated urban-scale terrains; the
experimental terrains live in an 8 m x 6 m lab, where the same vehicle would not fit
between the debris, so :func:`landing_params` scales everything down for them
(:data:`LAB`: a 0.25 m radius vehicle and 5 cm raster).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, replace
from typing import Any

import numpy as np

from alte.errors import ParameterError

__all__ = ["LAB", "QUADROTOR", "LandingParams", "landing_params"]

_RULES: dict[str, tuple[str, Any]] = {
    "radius": ("radius > 0", lambda v: v > 0),
    "margin": ("margin >= 0", lambda v: v >= 0),
    "clearance": ("clearance >= 0", lambda v: v >= 0),
    "max_slope_deg": ("0 < max_slope_deg < 90", lambda v: 0 < v < 90),
    "max_roughness": ("max_roughness > 0", lambda v: v > 0),
    "obstacle_height": ("obstacle_height > 0", lambda v: v > 0),
    "step": ("0 < step <= radius", None),
    "max_sites": ("max_sites >= 1", lambda v: v >= 1),
}


@dataclass(frozen=True)
class LandingParams:
    """What makes a safe landing site (module docstring); validated on creation.

    ``radius`` (m): vehicle footprint radius (the thesis' quadrotor: about 1 m with
    rotors); ``margin`` (m): added to the radius for position error, the disk that
    must be known and planar; ``clearance`` (m): free gap between the footprint's edge
    and the nearest obstacle; ``max_slope_deg``: steepest plane a skid can rest on;
    ``max_roughness`` (m): largest plane-fit residual std inside the disk;
    ``obstacle_height`` (m): height step above/below the ground plane that makes a
    pixel an obstacle; ``step`` (m): raster pixel size; ``max_sites``: sites chosen
    (the best ranked ones) and scored for precision.
    """

    radius: float = 1.0
    margin: float = 0.5
    clearance: float = 1.0
    max_slope_deg: float = 10.0
    max_roughness: float = 0.1
    obstacle_height: float = 0.3
    step: float = 0.25
    max_sites: int = 5

    def __post_init__(self) -> None:
        for name, (rule, check) in _RULES.items():
            value = getattr(self, name)
            kind = int if name == "max_sites" else float
            if isinstance(value, bool) or not isinstance(value, int | float | np.number):
                raise ParameterError(f"landing parameter {name}={value!r}: expected a number")
            if kind is int and int(value) != value:
                raise ParameterError(f"landing parameter {name}={value!r}: expected an integer")
            if not np.isfinite(value):
                raise ParameterError(f"landing parameter {name}={value!r}: must be finite")
            object.__setattr__(self, name, kind(value))
            ok = (0 < value <= self.radius) if name == "step" else check(value)
            if not ok:
                raise ParameterError(f"landing parameter {name}={value!r}: expected {rule}")

    @property
    def disk(self) -> float:
        """Radius (m) of the disk that must be known, planar and obstacle-free."""
        return self.radius + self.margin

    @property
    def keep_out(self) -> float:
        """Smallest distance (m) from a site centre to an obstacle."""
        return max(self.radius + self.clearance, self.disk)

    def as_dict(self) -> dict[str, Any]:
        """The parameters by name (for tables and results.json)."""
        return asdict(self)


#: The thesis' quadrotor over the simulated terrains (the defaults).
QUADROTOR = LandingParams()
#: A vehicle scaled to the 8 m x 6 m lab of the experimental terrains (thesis 2.2.4).
LAB = LandingParams(radius=0.25, margin=0.1, clearance=0.15, max_slope_deg=10.0,
                    max_roughness=0.03, obstacle_height=0.06, step=0.05)


def landing_params(terrain: str, **overrides: Any) -> LandingParams:
    """The preset for ``terrain`` (``exp_*``: :data:`LAB`, else :data:`QUADROTOR`), overridden."""
    base = LAB if terrain.startswith("exp_") else QUADROTOR
    unknown = sorted(set(overrides) - set(base.as_dict()))
    if unknown:
        raise ParameterError(f"unknown landing parameter {', '.join(unknown)}; valid: "
                             f"{', '.join(base.as_dict())}")
    return replace(base, **overrides)
