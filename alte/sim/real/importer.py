"""Import real terrain tiles as a terrain folder, the same kind as the built-in eight.

:func:`import_terrain` reads the tiles (:mod:`~alte.sim.real.tiles`), grids their bare
earth, object surface and objects (:mod:`~alte.sim.real.surface`), shifts them to a
local origin (the tiles' centre rounded to 1 km, as every georeferenced cloud in alte)
and plans the thesis' mission over them (:mod:`~alte.sim.real.flight`): a
:class:`~alte.sim.terrains.Terrain` whose scene is the labelled object surface.
:func:`write_imported` flies it and writes ``DIR/NAME/`` with the built-in terrains'
files (``bag/``, ``ground_truth.ply``, ``scenario.json``) plus ``bare_earth.npz`` (the
bare-earth grid in local metres); ``scenario.json`` adds ``kind: real`` and
``source``: every tile with its SHA-256, the CRS and units, the local origin, the grid,
which points were called ground and how (the class, the pair's file, or the ground
filter with its method, settings, source and alte's version) and the flight.
:mod:`~alte.sim.real.folder` reads such a folder back.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from alte.errors import SimulationError
from alte.io.points.pointformats import local_origin
from alte.sim.meta import SCENARIO_FILE
from alte.sim.real.flight import Flight, flight_plan
from alte.sim.real.folder import BARE_EARTH_FILE
from alte.sim.real.ground import GroundChoice, terrain_tiles
from alte.sim.real.surface import MIN_OBJECT, Surfaces, grid_surfaces, surface_mesh
from alte.sim.terrains import Terrain, TerrainSpec
from alte.types import JSONDict

__all__ = ["Imported", "import_terrain", "write_imported"]

#: Registration voxel (m) of imported terrains: the built-in ones' (0.12-0.185 m).
_VOXEL = {"lan": 0.15, "nav": 0.2}


@dataclass(eq=False)
class Imported:
    """An imported terrain: the terrain to fly, its surfaces, origin and provenance."""

    terrain: Terrain
    surfaces: Surfaces
    origin: NDArray[np.float64]
    source: JSONDict


def _crop_box(surfaces: Surfaces, origin: NDArray[np.float64]) -> tuple[float, ...]:
    xs, ys = surfaces.axes()
    lo = np.array([xs[0], ys[0], float(surfaces.ground.min()) - 1.0]) - origin
    hi = np.array([xs[-1], ys[-1], float(surfaces.top.max()) + 1.0]) - origin
    box: list[float] = np.round(np.concatenate([lo, hi]), 3).tolist()
    return tuple(box)


def import_terrain(paths: Sequence[str | os.PathLike[str]], flight: Flight | None = None, *,
                   name: str | None = None, crs: str | None = None,
                   ground: str | os.PathLike[str] | None = None,
                   ground_by: GroundChoice | None = None, cell: float | None = None,
                   region: Sequence[float] | None = None) -> Imported:
    """Read ``paths`` (one or several adjacent or overlapping tiles of one CRS), tell their
    ground (``ground``: a pair's ground file; ``ground_by``: class or filter,
    :mod:`~alte.sim.real.ground`) and plan ``flight`` over them (module docstring)."""
    flight = flight or Flight()
    tiles, told = terrain_tiles(paths, crs=crs, ground=ground, choice=ground_by,
                                region=region)
    surfaces = grid_surfaces(tiles, cell)
    xs, ys = surfaces.axes()
    corners = np.array([[xs[0], ys[0], surfaces.ground.min()],
                        [xs[-1], ys[-1], surfaces.top.max()]])
    # x, y: the centre to 1 km as every georeferenced cloud in alte; heights above a
    # round datum (100 m below the lowest ground), so the pipeline's own local frame
    # (its 1 km origin) leaves them where they are.
    origin = np.r_[local_origin(corners)[:2], np.floor(corners[0, 2] / 100.0) * 100.0]
    scene = surface_mesh(surfaces, origin)
    platform, frames, flight = flight_plan(surfaces, origin, flight)
    stem = name or f"{Path(paths[0]).stem.replace('-', '_')}_{flight.case}"
    title = (f"Real terrain {', '.join(Path(p).name for p in paths)}: "
             f"{flight.mission} mission")
    spec = TerrainSpec(stem, "real", title, flight.case, "real", frames, platform,
                       _crop_box(surfaces, origin), _VOXEL[flight.case])
    source: JSONDict = {
        "tiles": [t.about() for t in tiles], "units": tiles[0].units.as_dict(),
        "origin_m": origin.tolist(),
        "origin_note": "local = CRS coordinates scaled to metres minus origin_m",
        "grid": {"step_m": surfaces.step, "x0_m": surfaces.x0, "y0_m": surfaces.y0,
                 "shape": list(surfaces.shape),
                 "measured_ground_share": float(surfaces.measured.mean()),
                 "covered_share": float(surfaces.covered.mean()),
                 "min_object_m": MIN_OBJECT},
        "ground": told,
        "region": list(region) if region is not None else None,
        "flight": flight.as_dict(), "altitude_m": flight.height, "lane_spacing_m": flight.lanes,
        "objects": {c: sum(o.cls == c for o in scene.objects)
                    for c in sorted({o.cls for o in scene.objects})},
    }
    return Imported(Terrain(spec, scene), surfaces, origin, source)


def _write_bare_earth(imported: Imported) -> Callable[[Path], None]:
    def write(folder: Path) -> None:
        s, o = imported.surfaces, imported.origin
        np.savez_compressed(folder / BARE_EARTH_FILE, height=s.ground - o[2],
                            measured=s.measured, x0=s.x0 - o[0], y0=s.y0 - o[1], step=s.step)
    return write


def write_imported(imported: Imported, out_dir: str | os.PathLike[str] = "data", *,
                   seed: int = 0, frames: int | None = None, force: bool = False,
                   progress: bool = False, profile: object = None) -> Path:
    """Fly the imported terrain and write its folder (``out_dir/NAME``, or
    ``NAME-Nf``... as :func:`~alte.sim.scenario.terrain_folder` names it)."""
    from alte.sim.mission import simulate
    from alte.sim.profile import SensorProfile
    from alte.sim.scenario import terrain_folder, write_scenario

    chosen = profile if isinstance(profile, SensorProfile) else None
    name = imported.terrain.spec.name
    target = terrain_folder(out_dir, name, frames, seed, chosen)
    if target.exists() and not force:
        kind = "an imported terrain" if (target / SCENARIO_FILE).is_file() else "a folder"
        raise SimulationError(f"{target} exists ({kind}); force=True replaces it, or import "
                              "it under another name", setting="output.overwrite")
    sim = simulate(imported.terrain, seed=seed, frames=frames, progress=progress,
                   profile=chosen)
    extra: JSONDict = {"source": imported.source, "bare_earth": BARE_EARTH_FILE}
    return write_scenario(target, imported.terrain, sim, seed=seed, frames=frames,
                          progress=progress, extra=extra, more=_write_bare_earth(imported))
