"""alte-elevation: an elevation map with per-cell height variance, as an alte mapper plugin.

Installed beside alte (``pip install -e plugins/alte-elevation``), it is found by alte's
registry through the entry point ``alte.mappers: elevation`` and is then a mapper like
the built-in four: ``alte map BAG --mapper elevation --set resolution=0.25``.
"""

from alte_elevation.fusion import CellState, Gate, fuse
from alte_elevation.mapper import LAYERS, ElevationMap, ElevationSettings
from alte_elevation.noise import point_variance

__all__ = ["LAYERS", "CellState", "ElevationMap", "ElevationSettings", "Gate", "fuse",
           "point_variance"]
__version__ = "0.1.0"
