"""Real terrain: LiDAR tiles and DEMs imported as terrains the simulated UAV flies over.

:mod:`~alte.sim.real.tiles` reads the inputs into metres, :mod:`~alte.sim.real.surface`
grids the bare earth, the object surface and the objects and triangulates them,
:mod:`~alte.sim.real.flight` sizes the thesis' missions to the tile and
:mod:`~alte.sim.real.importer` writes the terrain folder (``alte simulate TILE ...``).
"""

from alte.sim.real.flight import MISSIONS, Flight, flight_plan
from alte.sim.real.importer import (
    BARE_EARTH_FILE,
    Imported,
    bare_earth,
    import_terrain,
    imported_terrain,
    write_imported,
)
from alte.sim.real.surface import CLASS_OF, Surfaces, grid_surfaces, surface_mesh
from alte.sim.real.tiles import GROUND_CLASS, Tile, Units, ground_mask, read_tiles

__all__ = ["BARE_EARTH_FILE", "CLASS_OF", "GROUND_CLASS", "MISSIONS", "Flight", "Imported",
           "Surfaces", "Tile", "Units", "bare_earth", "flight_plan", "grid_surfaces",
           "ground_mask", "import_terrain", "imported_terrain", "read_tiles", "surface_mesh",
           "write_imported"]
