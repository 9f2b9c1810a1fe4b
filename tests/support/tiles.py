"""Tiny hand-made terrain tiles: LAS/LAZ with classes, PCD pairs, DEM rasters.

Every tile is a flat field at a known height with one 6 m x 6 m building (class 6) of
known height in it, in a known CRS, so each reader's output can be checked exactly.
"""

import numpy as np

#: Metres per US survey foot.
US_FOOT = 1200 / 3937
#: A projected CRS in metres (UTM 32N) and one in US survey feet (California zone 3).
METRES, FEET = "EPSG:32632", "EPSG:2227"
GROUND_Z, ROOF = 250.0, 8.0
X0, Y0, SIDE = 500_000.0, 5_400_000.0, 60.0


def field(step=0.5, side=SIDE):
    """Ground points every ``step`` over the field and a building's roof points (z, class)."""
    g = np.arange(0.25, side, step)
    x, y = np.meshgrid(g, g)
    x, y = x.ravel(), y.ravel()
    roof = (np.abs(x - 30.0) < 3.0) & (np.abs(y - 30.0) < 3.0)
    z = np.where(roof, GROUND_Z + ROOF, GROUND_Z)
    cls = np.where(roof, 6, 2).astype(np.uint8)
    return np.column_stack([x + X0, y + Y0, z]), cls


def write_las(path, points, classes, crs=METRES, scale=1.0):
    """A LAS/LAZ tile (point format 1, every point a single return) with ``crs``."""
    import laspy
    import pyproj

    header = laspy.LasHeader(point_format=1, version="1.2")
    header.scales = np.array([0.001, 0.001, 0.001]) * scale
    header.offsets = np.floor(points.min(axis=0) / scale)
    if crs is not None:
        header.add_crs(pyproj.CRS.from_user_input(crs))
    las = laspy.LasData(header)
    las.x, las.y, las.z = (points[:, i] / scale for i in range(3))
    las.classification = classes
    las.return_number = np.ones(len(points), np.uint8)
    las.number_of_returns = np.ones(len(points), np.uint8)
    las.write(path)
    return path


def write_dem(path, height, *, x0=X0, y0=Y0, cell=1.0, crs=METRES, nodata=-9999.0):
    """A DEM raster (GeoTIFF or ESRI ASCII grid by suffix); ``height`` rows run north to
    south as rasters do."""
    import rasterio
    from affine import Affine

    driver = "AAIGrid" if str(path).endswith(".asc") else "GTiff"
    rows, cols = height.shape
    with rasterio.open(path, "w", driver=driver, height=rows, width=cols, count=1,
                       dtype="float64", crs=crs, nodata=nodata,
                       transform=Affine(cell, 0.0, x0, 0.0, -cell, y0 + rows * cell)) as out:
        out.write(np.where(np.isfinite(height), height, nodata), 1)
    return path
