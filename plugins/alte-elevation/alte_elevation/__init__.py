"""alte-elevation: an elevation map with per-cell height variance, as an alte mapper plugin.

Installed beside alte (``pip install -e plugins/alte-elevation``), it is found by alte's
registry through the entry point ``alte.mappers: elevation`` and is then a mapper like
the built-in four: ``alte map BAG --mapper elevation --set resolution=0.25``.
"""

import warnings

from alte_elevation.fusion import CellState, Gate, fuse
from alte_elevation.mapper import LAYERS, ElevationMap, ElevationSettings
from alte_elevation.noise import point_variance

__all__ = ["LAYERS", "CellState", "ElevationMap", "ElevationSettings", "Gate", "fuse",
           "point_variance"]
__version__ = "0.1.0"


def __getattr__(name: str) -> object:
    """``ElevationParams``: the first name of :class:`ElevationSettings` (deprecated)."""
    if name == "ElevationParams":
        warnings.warn("alte_elevation.ElevationParams is deprecated; use ElevationSettings",
                      DeprecationWarning, stacklevel=2)
        return ElevationSettings
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
