"""The shared real terrain tiles as sites, and the class of terrain each one is.

A :class:`Site` names the tiles of one terrain under ``../shared/realdata`` (one or
several adjacent LAS/LAZ tiles, or an ISPRS sample with its reference ground), the CRS
of tiles that state none, and the part imported (``region``, in the tiles' CRS units:
a crop of at most about 120 m x 120 m, so a site costs seconds; the ISPRS samples
whole). Its class is read off the imported surfaces by :func:`terrain_class`
(:data:`CLASSES`, in the order tested), except where the tile's classes cannot tell a
building from a tree (the ISPRS pairs: ground or not): there ``stated`` is the class
its source gives (Sithole & Vosselman 2004: samples 21 and 31 are urban blocks, 11 a
steep hillside with buildings, which the slope test finds):

* ``built-up``: buildings cover at least 5 % of the surface;
* ``steep``: the bare earth's median slope is at least 20 deg;
* ``slope``: at least 5 deg;
* ``flat under forest``: trees, vegetation and unclassified objects cover at least 30 %;
* ``flat open``: the rest.

Slopes are those of the bare-earth grid (central differences over its cells).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from alte.sim.real.surface import Surfaces

__all__ = ["CLASSES", "SITES", "Site", "surface_figures", "terrain_class"]

#: The terrain classes, in the order :func:`terrain_class` tests them.
CLASSES = ("built-up", "steep", "slope", "flat under forest", "flat open")
_BUILT, _STEEP, _SLOPE, _COVER = 0.05, 20.0, 5.0, 0.30


@dataclass(frozen=True)
class Site:
    """One real terrain: its tiles (paths relative to the real-data folder), the CRS
    of tiles without one, the reference ground of an ISPRS pair and the part imported."""

    name: str
    tiles: tuple[str, ...]
    crs: str | None = None
    ground: str | None = None
    region: tuple[float, float, float, float] | None = None
    note: str = ""
    stated: str | None = None


#: Every shared tile and ISPRS sample (SOURCES.md).
SITES: tuple[Site, ...] = (
    Site("ign_farmland", ("als/ign_lidarhd_farmland.laz",),
         region=(484860.0, 6632860.0, 484980.0, 6632980.0),
         note="IGN LiDAR HD, farmland with hedges and a few buildings"),
    Site("bcts_slope", ("als/bcts_forest/bcts_1.laz", "als/bcts_forest/bcts_2.laz"),
         region=(885040.0, 629340.0, 885160.0, 629460.0),
         note="BC Timber Sales forested slope, across two adjacent tiles"),
    Site("pyfor_forest", ("als/pyfor_flat_forest.laz",),
         region=(405040.0, 3276340.0, 405160.0, 3276460.0), note="flat ground under forest"),
    Site("hexbin_mountains", ("als/hexbin_mountains.las",),
         region=(393800.0, 3689100.0, 393920.0, 3689220.0),
         note="steep mountains, 0.65 points/m^2"),
    Site("dji_riparian", ("als/dji_l1_riparian.las",),
         note="drone survey (DJI Zenmuse L1), riparian vegetation, with a published DTM"),
    *(Site(f"isprs_{s}", (f"isprs_terrain/{s}-utm.pcd",), crs="EPSG:32632",
           ground=f"isprs_terrain/{s}-utm-ground.pcd",
           note="ISPRS filter test sample (Vaihingen/Stuttgart), reference ground",
           stated=stated)
      for s, stated in (("samp11", None), ("samp21", "built-up"), ("samp31", "built-up"))),
)


def surface_figures(surfaces: Surfaces) -> dict[str, float]:
    """The figures :func:`terrain_class` reads: median slope of the bare earth (deg),
    the shares of the covered cells under buildings and under other objects."""
    gy, gx = np.gradient(surfaces.ground, surfaces.step)
    slope = np.degrees(np.arctan(np.hypot(gx, gy)))[surfaces.covered]
    names = np.array([o.cls for o in surfaces.objects], dtype=object)[surfaces.label]
    names = names[surfaces.covered]
    return {"slope_deg": float(np.median(slope)),
            "building_share": float(np.mean(names == "building")),
            "cover_share": float(np.mean(np.isin(names, ("tree", "vegetation", "object"))))}


def terrain_class(surfaces: Surfaces, stated: str | None = None) -> str:
    """The class of a terrain (module docstring); ``stated`` where the classes cannot
    tell buildings from vegetation."""
    if stated is not None:
        return stated
    f = surface_figures(surfaces)
    if f["building_share"] >= _BUILT:
        return "built-up"
    if f["slope_deg"] >= _STEEP:
        return "steep"
    if f["slope_deg"] >= _SLOPE:
        return "slope"
    return "flat under forest" if f["cover_share"] >= _COVER else "flat open"
