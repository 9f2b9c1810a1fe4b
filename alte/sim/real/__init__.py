"""Real terrain: LiDAR tiles and DEMs imported as terrains the simulated UAV flies over.

:mod:`~alte.sim.real.tiles` reads the inputs into metres, :mod:`~alte.sim.real.surface`
grids the bare earth, the object surface and the objects and triangulates them,
:mod:`~alte.sim.real.ground` tells their ground (the producer's class, else the ground
stage's filter), :mod:`~alte.sim.real.flight` sizes the thesis' missions to the tile and
:mod:`~alte.sim.real.importer` writes the terrain folder (``alte simulate TILE ...``) and
:mod:`~alte.sim.real.folder` reads it back.
"""

from alte.sim.real.flight import MISSIONS, Flight, flight_plan
from alte.sim.real.folder import BARE_EARTH_FILE, bare_earth, imported_terrain
from alte.sim.real.ground import GroundChoice, crop_tiles, terrain_tiles
from alte.sim.real.importer import Imported, import_terrain, write_imported
from alte.sim.real.surface import CLASS_OF, Surfaces, grid_surfaces, surface_mesh
from alte.sim.real.tiles import GROUND_CLASS, Tile, Units, read_tiles

__all__ = ["BARE_EARTH_FILE", "CLASS_OF", "GROUND_CLASS", "MISSIONS", "Flight",
           "GroundChoice", "Imported", "Surfaces", "Tile", "Units", "bare_earth",
           "crop_tiles", "flight_plan", "grid_surfaces", "import_terrain", "imported_terrain",
           "read_tiles", "surface_mesh", "terrain_tiles", "write_imported"]
