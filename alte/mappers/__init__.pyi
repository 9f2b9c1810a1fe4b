from .alte2d import Alte2D
from .alte3d import Alte3D
from .base import CellCounts, Cells, Cost, Feed, Mapper
from .domain import Domain, DomainUse
from .octomap import Octomap
from .quadtree import Quadtree
from .registry import MAPPERS, MapperClass, check_export, export_map, make_mapper, mapper_class

__all__ = ["MAPPERS", "Alte2D", "Alte3D", "CellCounts", "Cells", "Cost", "Domain",
           "DomainUse", "Feed", "Mapper", "MapperClass", "Octomap", "Quadtree", "check_export",
           "export_map", "make_mapper", "mapper_class"]
