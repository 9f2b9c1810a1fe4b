"""Read an imported terrain's folder back (``alte simulate TILE ...`` wrote it).

:func:`imported_terrain` gives its :class:`~alte.sim.terrains.Terrain` (mesh and mission),
so other seeds, scan counts and sensor profiles of it are flown like any terrain's
(:func:`alte.sim.scenario.ensure_terrain`); :func:`bare_earth` its bare-earth grid. This
module sits below :mod:`alte.sim.scenario`, which reads imported terrains by name.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from alte.errors import SimulationError
from alte.sim.groundtruth import load_ground_truth
from alte.sim.meta import SCENARIO_FILE
from alte.sim.platform import Quadrotor
from alte.sim.terrains import Terrain, TerrainSpec

__all__ = ["BARE_EARTH_FILE", "bare_earth", "imported_terrain"]

#: The bare-earth grid of an imported terrain, in local metres.
BARE_EARTH_FILE = "bare_earth.npz"


def _platform(found: dict[str, list[list[float]] | list[float] | float | None]
              ) -> Quadrotor:
    heights, points = found.get("heights"), found["waypoints"]
    altitude, ramp = found["altitude"], found["ramp_s"]
    if not (isinstance(points, list) and isinstance(altitude, float | int)
            and isinstance(ramp, float | int) and (heights is None or isinstance(heights, list))):
        raise TypeError("platform: waypoints, altitude, ramp_s or heights malformed")
    return Quadrotor(tuple((float(p[0]), float(p[1])) for p in points  # type: ignore[index]
                           ), float(altitude), float(ramp),
                     tuple(float(h) for h in heights) if heights else None)  # type: ignore[arg-type]


def imported_terrain(folder: str | os.PathLike[str]) -> Terrain:
    """The :class:`Terrain` of an imported terrain folder (its mesh and mission)."""
    where = Path(folder)
    try:
        meta = json.loads((where / SCENARIO_FILE).read_text())
        spec = meta["spec"]
        if meta.get("kind") != "real":
            raise SimulationError(f"{where}: not an imported terrain (kind {meta.get('kind')!r})")
        terrain_spec = TerrainSpec(
            spec["name"], spec["section"], spec["title"], spec["case"], spec["kind"],
            int(spec["frames"]), _platform(spec["platform"]),
            tuple(float(v) for v in spec["crop_box"]), float(spec["registration_voxel"]))
    except (OSError, ValueError, KeyError, TypeError) as err:
        raise SimulationError(f"{where}: not a readable imported terrain ({err})") from err
    return Terrain(terrain_spec, load_ground_truth(where))


def bare_earth(folder: str | os.PathLike[str]) -> tuple[NDArray[np.float64], float, float,
                                                         float]:
    """The bare-earth grid of an imported terrain: heights (rows along y), x0, y0 (its
    south-west corner, local metres) and the cell (m)."""
    try:
        with np.load(Path(folder) / BARE_EARTH_FILE) as data:
            return (np.asarray(data["height"], np.float64), float(data["x0"]),
                    float(data["y0"]), float(data["step"]))
    except OSError as err:
        raise SimulationError(f"{folder}: no {BARE_EARTH_FILE} (not an imported terrain)") \
            from err
