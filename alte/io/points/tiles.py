"""Terrain tiles in and ground-classified LAS/LAZ out (``alte ground``).

:func:`read_tile` reads any point file alte reads; a LAS/LAZ tile is kept whole (every
dimension and record of its header) with the coordinate reference system its header
names. The filters work in metres, so :func:`tile_crs` refuses what would make their
settings wrong: a LAS/LAZ tile whose header names no CRS (its units are unknown) unless
the caller names one, a geographic CRS (degrees) and a projected one in feet.

:func:`write_classified` writes the tile as LAS/LAZ with ASPRS classes 2 (ground) and 1
(unclassified) and the classification's provenance (method, settings and their source,
alte's version, the input) as a JSON variable-length record (user ``alte``, record 1);
a LAS/LAZ input keeps every other dimension and record, other inputs become LAS 1.4
point format 6 with the CRS given. Atomic; an existing file is replaced only when asked.
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from alte.errors import ParameterError, PointFileError
from alte.fsutil import atomic_path
from alte.io.points.pointfiles import read_points_info

if TYPE_CHECKING:
    import laspy
    import pyproj

__all__ = ["GROUND_CLASS", "OTHER_CLASS", "PROVENANCE_RECORD", "RASTER_SUFFIXES", "Tile",
           "read_provenance", "read_tile", "tile_crs", "write_classified"]

GROUND_CLASS, OTHER_CLASS = 2, 1
#: (user id, record id) of the provenance record in the written LAS header.
PROVENANCE_RECORD = ("alte", 1)
#: Raster suffixes (a DEM passed where points are expected is named as such).
RASTER_SUFFIXES = (".asc", ".tif", ".tiff", ".dem", ".img", ".vrt", ".nc", ".grd")
_LAS = (".las", ".laz")


@dataclass(frozen=True, eq=False)
class Tile:
    """A point file's finite points (N, 3), its LAS content when it is LAS/LAZ (rows as
    ``points``) and the CRS its header names (None: none, or a format without one)."""

    path: Path
    points: NDArray[np.float64]
    las: laspy.LasData | None
    crs: pyproj.CRS | None


def read_tile(path: str | os.PathLike[str]) -> Tile:
    """Read a LAS/LAZ/PCD/PLY/npz/xyz tile; a raster DEM is refused by name."""
    path = Path(path)
    if path.suffix.lower() in RASTER_SUFFIXES:
        raise PointFileError(f"{path}: a raster ({path.suffix}), a DEM or an image, not a "
                             "point cloud; a ground filter classifies the raw LiDAR points")
    if path.suffix.lower() not in _LAS:
        return Tile(path, read_points_info(path).points, None, None)
    if not path.is_file():
        raise PointFileError(f"{path}: no such point file")
    import laspy

    try:
        las = laspy.read(path)
    except Exception as err:  # laspy's errors for a damaged file
        raise PointFileError(f"{path}: unreadable LAS/LAZ ({type(err).__name__}: {err})") \
            from err
    points = np.column_stack([np.asarray(las.x), np.asarray(las.y), np.asarray(las.z)])
    if len(points) == 0:
        raise PointFileError(f"{path}: no points (empty or unreadable file)")
    finite = np.isfinite(points).all(axis=1)
    if not finite.all():
        las = las[finite] if finite.any() else las
        points = points[finite]
    try:
        crs = las.header.parse_crs()
    except Exception as err:  # pyproj's errors for a malformed WKT / GeoTIFF record
        raise PointFileError(f"{path}: its coordinate reference system record is "
                             f"unreadable ({type(err).__name__}: {err})") from err
    return Tile(path, points, las, crs)


def _units(crs: pyproj.CRS) -> tuple[str, float]:
    """Name and metres per unit of a CRS's first axis."""
    axis = crs.axis_info[0]
    return axis.unit_name, float(axis.unit_conversion_factor)


def tile_crs(tile: Tile, given: str | None, flag: str = "--crs") -> pyproj.CRS | None:
    """The tile's CRS (its header's, else ``given``), checked to be projected in metres;
    a LAS/LAZ tile needs one; errors name ``flag``."""
    import pyproj

    if given is not None and tile.crs is not None:
        raise ParameterError(f"{flag} {given}: {tile.path} already names its CRS "
                             f"({tile.crs.name}); leave {flag} out")
    crs = tile.crs
    if given is not None:
        try:
            crs = pyproj.CRS.from_user_input(given)
        except pyproj.exceptions.CRSError as err:
            raise ParameterError(f"{flag} {given!r}: not a coordinate reference system "
                                 "(e.g. EPSG:32632)") from err
    if crs is None:
        if tile.las is not None:
            raise ParameterError(
                f"{tile.path}: its LAS header names no coordinate reference system, so the "
                f"units of its coordinates are unknown (the filters' settings are metres); "
                f"name it with {flag} EPSG:CODE (a projected CRS in metres)")
        return None
    horizontal = crs.sub_crs_list[0] if crs.is_compound else crs
    if horizontal.is_geographic:
        raise ParameterError(f"{tile.path}: coordinates in degrees ({horizontal.name}); "
                             "reproject the tile to a projected CRS in metres first")
    unit, factor = _units(horizontal)
    if abs(factor - 1.0) > 1e-9:
        raise ParameterError(f"{tile.path}: coordinates in {unit} ({horizontal.name}); "
                             "reproject the tile to a projected CRS in metres first")
    return crs


def _new_las(points: NDArray[np.float64], crs: pyproj.CRS | None) -> laspy.LasData:
    import laspy

    from alte.io.points.pointformats import local_origin

    header = laspy.LasHeader(point_format=6, version="1.4")
    header.offsets = local_origin(points)
    header.scales = np.full(3, 1e-4)
    if crs is not None:
        header.add_crs(crs)
    las = laspy.LasData(header)
    las.x, las.y, las.z = points[:, 0], points[:, 1], points[:, 2]
    return las


def write_classified(path: str | os.PathLike[str], tile: Tile, ground: NDArray[np.bool_],
                     provenance: dict[str, object], *, crs: pyproj.CRS | None = None,
                     overwrite: bool = False) -> Path:
    """Write ``tile`` with classes 2 / 1 from ``ground`` and ``provenance`` in its header."""
    import laspy

    path = Path(path)
    if path.suffix.lower() not in _LAS:
        raise ParameterError(f"output {path}: a classified tile is LAS or LAZ (.las, .laz)",
                             setting="output.path")
    if path.exists() and tile.path.exists() and path.resolve() == tile.path.resolve():
        raise ParameterError(f"output {path}: the input itself; write to another file",
                             setting="output.path")
    if len(ground) != len(tile.points):
        raise ParameterError(f"{len(ground)} labels for {len(tile.points)} points")
    las = tile.las if tile.las is not None else _new_las(tile.points, crs)
    if tile.las is not None and tile.crs is None and crs is not None:
        las.header.add_crs(crs)
    las.classification = np.where(ground, GROUND_CLASS, OTHER_CLASS).astype(np.uint8)
    record = json.dumps(provenance, sort_keys=True, default=str).encode()
    las.header.vlrs = [v for v in las.header.vlrs
                       if (v.user_id, v.record_id) != PROVENANCE_RECORD]
    las.header.vlrs.append(laspy.VLR(PROVENANCE_RECORD[0], PROVENANCE_RECORD[1],
                                     "ground classification", record))
    las.header.generating_software = "alte ground"
    with atomic_path(path, overwrite=overwrite) as tmp, open(tmp, "wb") as fh:
        las.write(fh, do_compress=path.suffix.lower() == ".laz")
    return path


def read_provenance(path: str | os.PathLike[str]) -> dict[str, object] | None:
    """The provenance record :func:`write_classified` wrote into ``path`` (None: none)."""
    import laspy

    with laspy.open(path) as reader:
        for vlr in reader.header.vlrs:
            if (vlr.user_id, vlr.record_id) == PROVENANCE_RECORD:
                found: dict[str, object] = json.loads(bytes(vlr.record_data))
                return found
    return None
