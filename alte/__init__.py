"""alte: Adaptive Learning Terrain Estimation workbench for UAV LiDAR mapping."""

from alte.errors import AlteError
from alte.types import Frame, Mount, thesis_mount

__all__ = ["AlteError", "Frame", "Mount", "__version__", "thesis_mount"]

__version__ = "0.1.0"
