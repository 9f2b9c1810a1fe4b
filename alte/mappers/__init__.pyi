from . import registry
from .alte2d import Alte2D
from .alte3d import Alte3D
from .base import VARIANCE, CellCounts, Cells, Cost, Feed, Mapper
from .domain import Domain, DomainUse
from .export import check_export, export_map
from .octomap import Octomap
from .quadtree import Quadtree
from .registry import make_mapper

__all__ = ["VARIANCE", "Alte2D", "Alte3D", "CellCounts", "Cells", "Cost", "Domain", "DomainUse",
           "Feed", "Mapper", "Octomap", "Quadtree", "check_export", "export_map", "make_mapper",
           "registry"]
