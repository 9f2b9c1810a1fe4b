"""Import real terrain tiles as a terrain folder, the same kind as the built-in eight.

:func:`import_terrain` reads the tiles (:mod:`~alte.sim.real.tiles`), grids their bare
earth, object surface and objects (:mod:`~alte.sim.real.surface`), shifts them to a
local origin (the tiles' centre rounded to 1 km, as every georeferenced cloud in alte)
and plans the thesis' mission over them (:mod:`~alte.sim.real.flight`): a
:class:`~alte.sim.terrains.Terrain` whose scene is the labelled object surface.
:func:`write_imported` flies it and writes ``DIR/NAME/`` with the built-in terrains'
files (``bag/``, ``ground_truth.ply``, ``scenario.json``) plus ``bare_earth.npz`` (the
bare-earth grid in local metres); ``scenario.json`` adds ``kind: real`` and
``source``: every tile with its SHA-256, the CRS and units, the local origin, the grid
and the flight. :func:`imported_terrain` reads such a folder back as a
:class:`~alte.sim.terrains.Terrain`, so other seeds, scan counts and sensor profiles of
it are flown like any terrain's (:func:`alte.sim.scenario.ensure_terrain`).
"""

from __future__ import annotations

import json
import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from alte.errors import ParameterError, SimulationError
from alte.io.pointformats import local_origin
from alte.sim.platform import Quadrotor
from alte.sim.real.flight import Flight, flight_plan
from alte.sim.real.surface import MIN_OBJECT, Surfaces, grid_surfaces, surface_mesh
from alte.sim.real.tiles import GROUND_CLASS, Tile, read_tiles
from alte.sim.terrains import Terrain, TerrainSpec
from alte.types import JSONDict

__all__ = ["BARE_EARTH_FILE", "Imported", "bare_earth", "import_terrain", "imported_terrain",
           "write_imported"]

BARE_EARTH_FILE = "bare_earth.npz"
#: Registration voxel (m) of imported terrains: the built-in ones' (0.12-0.185 m).
_VOXEL = {"lan": 0.15, "nav": 0.2}


@dataclass(eq=False)
class Imported:
    """An imported terrain: the terrain to fly, its surfaces, origin and provenance."""

    terrain: Terrain
    surfaces: Surfaces
    origin: NDArray[np.float64]
    source: JSONDict


def _crop(tiles: list[Tile], region: Sequence[float] | None) -> list[Tile]:
    """Each tile's points inside ``region`` (x0, y0, x1, y1 in the tiles' CRS units)."""
    if region is None:
        return tiles
    x0, y0, x1, y1 = (float(region[i]) for i in range(4))
    if not (x1 > x0 and y1 > y0):
        raise ParameterError(f"--region {list(region)}: expected XMIN,YMIN,XMAX,YMAX with "
                             "XMIN < XMAX and YMIN < YMAX")
    out = []
    for t in tiles:
        f = t.units.horizontal_m
        xy = t.points[:, :2]
        keep = (xy[:, 0] >= x0 * f) & (xy[:, 0] <= x1 * f) & (xy[:, 1] >= y0 * f) & (
            xy[:, 1] <= y1 * f)
        if keep.any() and t.ground[keep].any():
            out.append(Tile(t.path, t.kind, t.units, t.points[keep], t.classes[keep],
                            t.first[keep], t.ground[keep], t.sha256, t.cell,
                            [*t.notes, f"cropped to --region {x0:g},{y0:g},{x1:g},{y1:g}"]))
    if not out:
        raise ParameterError(f"--region {list(region)}: no tile has ground points inside it "
                             "(the region is in the tiles' CRS units)")
    return out


def _crop_box(surfaces: Surfaces, origin: NDArray[np.float64]) -> tuple[float, ...]:
    xs, ys = surfaces.axes()
    lo = np.array([xs[0], ys[0], float(surfaces.ground.min()) - 1.0]) - origin
    hi = np.array([xs[-1], ys[-1], float(surfaces.top.max()) + 1.0]) - origin
    box: list[float] = np.round(np.concatenate([lo, hi]), 3).tolist()
    return tuple(box)


def import_terrain(paths: Sequence[str | os.PathLike[str]], flight: Flight | None = None, *,
                   name: str | None = None, crs: str | None = None,
                   ground: str | os.PathLike[str] | None = None,
                   ground_class: int = GROUND_CLASS, cell: float | None = None,
                   region: Sequence[float] | None = None) -> Imported:
    """Read ``paths`` (one or several adjacent or overlapping tiles of one CRS) and plan
    ``flight`` over them (module docstring)."""
    flight = flight or Flight()
    tiles = _crop(read_tiles(list(paths), crs=crs, ground=ground, ground_class=ground_class),
                  region)
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
        "ground_class": ground_class if ground is None else None,
        "ground_file": str(ground) if ground is not None else None,
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
    from alte.sim.scenario import SCENARIO_FILE, terrain_folder, write_scenario

    chosen = profile if isinstance(profile, SensorProfile) else None
    name = imported.terrain.spec.name
    target = terrain_folder(out_dir, name, frames, seed, chosen)
    if target.exists() and not force:
        kind = "an imported terrain" if (target / SCENARIO_FILE).is_file() else "a folder"
        raise SimulationError(f"{target} exists ({kind}); pass --force to replace it, or "
                              "--name to import under another name")
    sim = simulate(imported.terrain, seed=seed, frames=frames, progress=progress,
                   profile=chosen)
    extra: JSONDict = {"source": imported.source, "bare_earth": BARE_EARTH_FILE}
    return write_scenario(target, imported.terrain, sim, seed=seed, frames=frames,
                          progress=progress, extra=extra, more=_write_bare_earth(imported))


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
    from alte.sim.groundtruth import load_ground_truth
    from alte.sim.scenario import SCENARIO_FILE

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
