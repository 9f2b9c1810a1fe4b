"""Real terrain tiles read into metres: LAS/LAZ with a ground class, an ISPRS-style pair, a DEM.

Every input becomes a :class:`Tile`: points in the tile's projected CRS scaled to metres
(not shifted), each with its ASPRS class, whether it is a first return and whether the
file calls it ground (its ground class, an ISPRS-style pair's ground file); a tile that
calls none ground is classified by :mod:`~alte.sim.real.ground`, the one place that
decides the import's ground. A DEM raster (GeoTIFF, ESRI ASCII grid; read with rasterio)
becomes the ground points at its cell centres. CRS
and units come from the file (LAS VLRs through laspy, the raster's own CRS or ``.prj``)
or from ``--crs``; pyproj says what one unit of each axis is in metres, so a tile in US
survey feet comes out in metres. Noise (ASPRS 7 and 18) and IGN LiDAR HD's artefact and
virtual points (65, 66) are dropped and counted.
"""

from __future__ import annotations

import hashlib
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from alte.errors import ParameterError, PointFileError
from alte.types import JSONDict

if TYPE_CHECKING:
    import pyproj

__all__ = ["DROPPED_CLASSES", "GROUND_CLASS", "POINT_SUFFIXES", "RASTER_SUFFIXES", "Tile",
           "Units", "read_tiles", "units_of"]

#: ASPRS class of bare-earth points.
GROUND_CLASS = 2
#: Classes dropped on reading: ASPRS low and high noise, IGN LiDAR HD artefacts and
#: virtual points.
DROPPED_CLASSES = (7, 18, 65, 66)
POINT_SUFFIXES = (".las", ".laz", ".pcd")
RASTER_SUFFIXES = (".tif", ".tiff", ".asc")


@dataclass(frozen=True)
class Units:
    """A tile's CRS and what one unit of its horizontal and vertical axes is in metres."""

    crs: str
    name: str
    horizontal: str
    horizontal_m: float
    vertical: str
    vertical_m: float

    def as_dict(self) -> JSONDict:
        """JSON-ready form (scenario.json's provenance)."""
        return {"crs": self.crs, "name": self.name, "horizontal_unit": self.horizontal,
                "horizontal_m_per_unit": self.horizontal_m, "vertical_unit": self.vertical,
                "vertical_m_per_unit": self.vertical_m}


@dataclass(eq=False)
class Tile:
    """One input in metres (module docstring); ``notes`` say what was dropped or assumed,
    ``ground_by`` how its ground was told (``class 2``, ``file NAME``, ``DEM``, ``filter
    smrf``)."""

    path: Path
    kind: str
    units: Units
    points: NDArray[np.float64]
    classes: NDArray[np.uint8]
    first: NDArray[np.bool_]
    ground: NDArray[np.bool_]
    sha256: str
    cell: float | None = None
    notes: list[str] = field(default_factory=list)
    ground_by: str = ""

    def about(self) -> JSONDict:
        """Provenance of the tile for scenario.json."""
        return {"file": str(self.path), "kind": self.kind, "sha256": self.sha256,
                "points": len(self.points), "ground_points": int(self.ground.sum()),
                "ground_by": self.ground_by, "crs": self.units.crs, "notes": list(self.notes)}


def units_of(crs: pyproj.CRS, where: str) -> Units:
    """The :class:`Units` of a projected ``crs`` (a geographic one is refused)."""
    if crs.is_geographic:
        raise ParameterError(f"{where}: CRS {crs.name} is geographic (degrees); reproject "
                             "the tile to a projected CRS in metres or feet (e.g. its UTM "
                             "zone) first")
    horizontal = crs.axis_info[0] if crs.axis_info else None
    if horizontal is None or not horizontal.unit_conversion_factor:
        raise ParameterError(f"{where}: CRS {crs.name} states no axis unit; name the CRS",
                             setting="import.crs")
    vertical = horizontal
    if crs.is_compound and len(crs.sub_crs_list) > 1 and crs.sub_crs_list[1].axis_info:
        vertical = crs.sub_crs_list[1].axis_info[0]
    code = crs.to_authority()
    return Units(":".join(code) if code else crs.to_wkt(), crs.name, horizontal.unit_name,
                 float(horizontal.unit_conversion_factor), vertical.unit_name,
                 float(vertical.unit_conversion_factor))


def _crs(found: pyproj.CRS | None, given: str | None, where: str) -> Units:
    """The file's CRS, else ``--crs``; both and different: refused."""
    import pyproj

    if given is not None:
        try:
            chosen = pyproj.CRS.from_user_input(given)
        except pyproj.exceptions.CRSError as err:
            raise ParameterError(f"import: crs={given!r}: not a CRS pyproj knows ({err})",
                                 setting="import.crs") from err
        if found is not None and not found.equals(chosen, ignore_axis_order=True):
            raise ParameterError(f"{where}: the file's CRS is {found.name}, not crs="
                                 f"{given!r}; leave crs out for this tile",
                                 setting="import.crs")
        return units_of(chosen, where)
    if found is None:
        raise ParameterError(f"{where}: no CRS in the file; name the CRS (e.g. EPSG:32632) "
                             "its coordinates and units are in", setting="import.crs")
    return units_of(found, where)


def _digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _scaled(points: NDArray[np.float64], units: Units) -> NDArray[np.float64]:
    scale = np.array([units.horizontal_m, units.horizontal_m, units.vertical_m])
    scaled: NDArray[np.float64] = points * scale
    return scaled


def _keep(tile_points: NDArray[np.float64], classes: NDArray[np.uint8],
          first: NDArray[np.bool_], notes: list[str]
          ) -> tuple[NDArray[np.float64], NDArray[np.uint8], NDArray[np.bool_]]:
    drop = np.isin(classes, DROPPED_CLASSES)
    if drop.any():
        notes.append(f"{int(drop.sum()):,} noise, artefact or virtual points (classes "
                     f"{', '.join(str(c) for c in DROPPED_CLASSES)}) dropped")
    return tile_points[~drop], classes[~drop], first[~drop]


def _read_las(path: Path, crs: str | None, ground_class: int) -> Tile:
    import laspy

    try:
        las = laspy.read(path)
        found = las.header.parse_crs()
    except (OSError, laspy.errors.LaspyException) as err:
        raise PointFileError(f"{path}: cannot read as LAS/LAZ ({err})") from err
    units = _crs(found, crs, str(path))
    notes: list[str] = []
    pts = np.column_stack([np.asarray(las.x), np.asarray(las.y), np.asarray(las.z)])
    classes = np.asarray(las.classification, dtype=np.uint8)
    first = np.asarray(las.return_number) == 1
    if not first.any():
        first = np.ones(len(pts), dtype=bool)
        notes.append("no point is flagged a first return: every point counts as one")
    pts, classes, first = _keep(pts, classes, first, notes)
    return Tile(path, "las", units, _scaled(pts, units), classes, first,
                classes == ground_class, _digest(path), notes=notes,
                ground_by=f"class {ground_class}")


def _read_pair(path: Path, ground_file: Path, crs: str | None) -> Tile:
    """All points plus a file of the reference ground among them (the ISPRS filter test)."""
    from scipy.spatial import cKDTree

    from alte.io.points.pointfiles import read_points

    units = _crs(None, crs, str(path))
    pts, ground_pts = read_points(path), read_points(ground_file)
    dist, _ = cKDTree(ground_pts).query(pts, distance_upper_bound=1e-3, workers=-1)
    ground = np.isfinite(dist)
    if not ground.any():
        raise PointFileError(f"ground file {ground_file}: none of its points is in {path}; "
                             "give the bare-earth subset of that tile's points",
                             setting="import.ground_file")
    classes = np.where(ground, GROUND_CLASS, 1).astype(np.uint8)
    notes = [f"ground: the {int(ground.sum()):,} points also in {ground_file.name}"]
    return Tile(path, "pair", units, _scaled(pts, units), classes, np.ones(len(pts), bool),
                ground, _digest(path), notes=notes, ground_by=f"file {ground_file}")


def _read_raster(path: Path, crs: str | None) -> Tile:
    import rasterio
    from rasterio.errors import RasterioIOError

    try:
        with rasterio.open(path) as src:
            band = src.read(1, masked=True).astype(np.float64)
            transform, found = src.transform, src.crs
    except RasterioIOError as err:
        raise PointFileError(f"{path}: cannot read as a DEM raster ({err})") from err
    import pyproj

    units = _crs(pyproj.CRS.from_wkt(found.to_wkt()) if found else None, crs, str(path))
    valid = ~np.ma.getmaskarray(band) & np.isfinite(band.filled(np.nan))
    if not valid.any():
        raise PointFileError(f"{path}: every cell is nodata; the DEM holds no height")
    rows, cols = np.nonzero(valid)
    xs, ys = rasterio.transform.xy(transform, rows, cols, offset="center")
    pts = np.column_stack([np.asarray(xs, float), np.asarray(ys, float),
                           band.data[rows, cols]])
    cell = float(abs(transform.a)) * units.horizontal_m
    n = len(pts)
    notes = [f"{int((~valid).sum()):,} nodata cells"] if (~valid).any() else []
    return Tile(path, "raster", units, _scaled(pts, units),
                np.full(n, GROUND_CLASS, np.uint8), np.ones(n, bool), np.ones(n, bool),
                _digest(path), cell, notes, "DEM")


def read_tiles(paths: list[str | os.PathLike[str]], *, crs: str | None = None,
               ground: str | os.PathLike[str] | None = None,
               ground_class: int = GROUND_CLASS) -> list[Tile]:
    """Read every tile (module docstring); all must share one CRS. ``ground`` is the
    bare-earth file of a single point tile (an ISPRS-style pair); a LAS/LAZ tile's ground
    is class ``ground_class`` (none may be: :mod:`~alte.sim.real.ground` decides)."""
    if not paths:
        raise ParameterError("no tile given: name one or more LAS/LAZ, PCD or DEM files")
    if ground is not None and len(paths) != 1:
        raise ParameterError("a ground file pairs one tile with its bare-earth points; "
                             "import one tile at a time with it", setting="import.ground_file")
    tiles = [_read_one(Path(p), crs, ground, ground_class) for p in paths]
    crss = {t.units.crs for t in tiles}
    if len(crss) > 1:
        listed = "; ".join(f"{t.path.name}: {t.units.crs}" for t in tiles)
        raise ParameterError(f"tiles in different CRSs ({listed}); reproject them to one "
                             "first, or import them separately")
    return tiles


def _read_one(path: Path, crs: str | None, ground: str | os.PathLike[str] | None,
              ground_class: int) -> Tile:
    if not path.is_file():
        raise PointFileError(f"{path}: no such tile")
    suffix = path.suffix.lower()
    if ground is not None:
        return _read_pair(path, Path(ground), crs)
    if suffix in (".las", ".laz"):
        return _read_las(path, crs, ground_class)
    if suffix in RASTER_SUFFIXES:
        return _read_raster(path, crs)
    if suffix == ".pcd":
        raise ParameterError(f"{path}: a PCD has no classes; give a ground file with its "
                             "bare-earth points (an ISPRS-style pair)",
                             setting="import.ground_file")
    raise ParameterError(f"{path}: not a terrain tile; expected LAS/LAZ "
                         f"({', '.join(POINT_SUFFIXES)}) or a DEM ({', '.join(RASTER_SUFFIXES)})")
