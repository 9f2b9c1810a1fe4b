"""The thesis' missions flown over a real surface, sized to it.

The built-in terrains fix what a mission is: the quadrotor at 10 m (landing, sim_lan_1)
or 14 m (navigation, sim_nav_1) at about 5 m/s (5.2 m/s on both), with the thesis' sensor
mount, a lawnmower whose lanes lie 24-26 m apart at 10 m (2.5 x the altitude) for
landing, a loop along the scene's edges and a pass through its middle for navigation.
Over a real tile the same patterns span the tile (lanes along its longer side, 2.5 x
the altitude apart). The altitude is the thesis' over a tile of the thesis' size and
grows with a larger tile as the built-in scenes relate to theirs (their shorter side is
7 x the altitude for landing, 5 x for navigation), so the pattern keeps the thesis'
three lanes, up to :data:`MAX_ALTITUDE`, where most of the VLP-16's beams (15-45 deg
below the horizon on the thesis' mount) still reach the ground within its 100 m range.
The altitude is above the bare earth under the vehicle, never less than ``clearance``
above the highest object within ``reach`` of it: the vehicle follows the terrain and
climbs over trees and roofs before it reaches them, as a survey UAV does. The number of
scans follows from the path's length and the speed.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass
from typing import ClassVar, Literal

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage

from alte.params import Record, param
from alte.sim.platform import Quadrotor, Trajectory
from alte.sim.real.surface import Surfaces

__all__ = ["MAX_ALTITUDE", "MISSIONS", "Flight", "flight_plan"]

#: Mission name -> (case, altitude above the bare earth in m, shorter side of the scene
#: over the altitude), from sim_lan_1 (70 m at 10 m) and sim_nav_1 (70 m at 14 m).
MISSIONS: dict[str, tuple[str, float, float]] = {"landing": ("lan", 10.0, 7.0),
                                                 "navigation": ("nav", 14.0, 5.0)}
#: The highest altitude a mission is sized to (m above the bare earth).
MAX_ALTITUDE = 40.0
_PROFILE_STEP = 2.0  # m of path between two points of the height profile
_RATE_HZ = 10.0


def _positive(value: float) -> bool:
    return value > 0


@dataclass(frozen=True)
class Flight(Record):
    """How the mission is flown over the tile (module docstring); unset: the thesis'."""

    OWNER: ClassVar[str] = "flight"
    mission: Literal["landing", "navigation"] = param("landing", help="landing or navigation")
    altitude: float | None = param(None, _positive, "> 0",
                                   "m above the bare earth (default: 10 landing, 14 navigation, "
                                   "higher over larger tiles)")
    speed: float = param(5.0, _positive, "> 0", "cruise speed, m/s")
    spacing: float | None = param(None, _positive, "> 0",
                                  "m between lawnmower lanes (default 2.5 x the altitude)")
    clearance: float = param(3.0, lambda v: v >= 0, ">= 0",
                             "least height above the highest object within reach, m")
    reach: float = param(10.0, lambda v: v >= 0, ">= 0",
                         "m around the vehicle whose objects it climbs over")

    @property
    def case(self) -> str:
        """``lan`` or ``nav``."""
        return MISSIONS[self.mission][0]

    @property
    def height(self) -> float:
        """The altitude above the bare earth (m; unsized: the thesis')."""
        return self.altitude if self.altitude is not None else MISSIONS[self.mission][1]

    def sized(self, short_side: float) -> Flight:
        """This flight with its altitude sized to a tile whose shorter side is
        ``short_side`` metres (module docstring), unless one was given."""
        if self.altitude is not None:
            return self
        _, thesis, ratio = MISSIONS[self.mission]
        return self.replace(altitude=float(np.clip(round(short_side / ratio, 1), thesis,
                                                   MAX_ALTITUDE)))

    @property
    def lanes(self) -> float:
        """The lane spacing (m)."""
        return self.spacing if self.spacing is not None else 2.5 * self.height


def _densify(corners: list[tuple[float, float]], step: float) -> list[tuple[float, float]]:
    """Points every ``step`` m along straight legs, so the spline keeps the legs straight."""
    out = [corners[0]]
    for a, b in itertools.pairwise(corners):
        n = max(1, int(np.ceil(np.hypot(b[0] - a[0], b[1] - a[1]) / step)))
        out += [(a[0] + (b[0] - a[0]) * k / n, a[1] + (b[1] - a[1]) * k / n)
                for k in range(1, n + 1)]
    return out


def _pattern(box: tuple[float, float, float, float], flight: Flight) -> list[tuple[float, float]]:
    """Lawnmower (landing) or edge loop and middle pass (navigation) inside ``box``."""
    x0, y0, x1, y1 = box
    swap = (y1 - y0) > (x1 - x0)  # lanes along the longer side
    (a0, a1), (b0, b1) = ((y0, y1), (x0, x1)) if swap else ((x0, x1), (y0, y1))
    inset = min(0.5 * flight.lanes, 0.25 * (b1 - b0))
    end = min(0.5 * flight.lanes, 0.25 * (a1 - a0))
    if flight.mission == "landing":
        n = max(2, int(np.ceil((b1 - b0 - 2 * inset) / flight.lanes)) + 1)
        across = np.linspace(b0 + inset, b1 - inset, n)
        corners = []
        for i, b in enumerate(across):
            ends = (a0 + end, a1 - end) if i % 2 == 0 else (a1 - end, a0 + end)
            corners += [(ends[0], float(b)), (ends[1], float(b))]
    else:
        mid = 0.5 * (b0 + b1)
        corners = [(a0 + end, b0 + inset), (a1 - end, b0 + inset), (a1 - end, b1 - inset),
                   (a0 + end, b1 - inset), (a0 + end, mid), (a1 - end, mid)]
    corners = [(b, a) for a, b in corners] if swap else corners
    return _densify(corners, 0.5 * flight.lanes)


def _clear_heights(surfaces: Surfaces, flight: Flight) -> tuple[NDArray[np.float64],
                                                                 NDArray[np.float64]]:
    """Per cell the height to fly at: the altitude above the bare earth, or the
    clearance above the highest object within reach."""
    size = 2 * int(np.ceil(flight.reach / surfaces.step)) + 1
    over = ndimage.maximum_filter(surfaces.top, size=size, mode="nearest") + flight.clearance
    return np.maximum(surfaces.ground + flight.height, over), over


def _profile(traj: Trajectory, surfaces: Surfaces, origin: NDArray[np.float64],
             flight: Flight) -> tuple[float, ...]:
    first, last = traj.parameter_range
    n = max(2, int(np.ceil((last - first) / _PROFILE_STEP)) + 1)
    xy = traj.path_xy(np.linspace(first, last, n)) + origin[:2]
    wanted, _ = _clear_heights(surfaces, flight)
    ny, nx = surfaces.shape
    col = np.clip(((xy[:, 0] - surfaces.x0) / surfaces.step).astype(int), 0, nx - 1)
    row = np.clip(((xy[:, 1] - surfaces.y0) / surfaces.step).astype(int), 0, ny - 1)
    z = wanted[row, col] - origin[2]
    ahead = 2 * int(np.ceil(flight.reach / _PROFILE_STEP)) + 1
    z = ndimage.maximum_filter1d(z, ahead, mode="nearest")  # climb before, descend after
    z = ndimage.uniform_filter1d(z, ahead, mode="nearest")
    return tuple(float(v) for v in np.round(z, 3))


def flight_plan(surfaces: Surfaces, origin: NDArray[np.float64], flight: Flight
                ) -> tuple[Quadrotor, int, Flight]:
    """The quadrotor's path over ``surfaces`` (local coordinates), the mission's scans and
    the flight sized to the tile."""
    xs, ys = surfaces.axes()
    box = (float(xs[0] - origin[0]), float(ys[0] - origin[1]), float(xs[-1] - origin[0]),
           float(ys[-1] - origin[1]))
    flight = flight.sized(min(box[2] - box[0], box[3] - box[1]))
    waypoints = tuple(_pattern(box, flight))
    flat = Quadrotor(waypoints, flight.height)
    length = Trajectory(flat, 100.0).length
    ramp = flat.ramp_s
    duration = length / flight.speed + ramp
    frames = int(np.ceil(duration * _RATE_HZ))
    traj = Trajectory(flat, frames / _RATE_HZ)
    plan = Quadrotor(waypoints, flight.height, heights=_profile(traj, surfaces, origin, flight))
    return plan, frames, flight
