"""Importing real terrain tiles: every input format, units, overlapping tiles, bad input."""

import numpy as np
import pytest
from support.tiles import (
    FEET,
    GROUND_Z,
    ROOF,
    SIDE,
    US_FOOT,
    X0,
    Y0,
    field,
    write_dem,
    write_las,
)

from alte.cli import main
from alte.errors import ParameterError, PointFileError
from alte.io.points.pointfiles import write_points
from alte.paths import realdata_dir
from alte.sim.real import Flight, grid_surfaces, import_terrain, read_tiles


def _building(imported, cls="building"):
    """The one object's top above the bare earth and its footprint cells."""
    s = imported.surfaces
    names = [o.cls for o in s.objects]
    building = names.index(cls)
    cells = s.label == building
    return float(s.top[cells].max() - s.ground[cells].mean()), int(cells.sum())


@pytest.mark.parametrize("suffix", [".las", ".laz"])
def test_las_and_laz_give_bare_earth_object_surface_and_objects(tmp_path, suffix):
    pts, cls = field()
    tile = write_las(tmp_path / f"field{suffix}", pts, cls)
    imported = import_terrain([tile], Flight(), cell=1.0)
    s = imported.surfaces
    assert np.allclose(s.ground, GROUND_Z, atol=1e-3)  # under the roof too
    height, cells = _building(imported)
    assert height == pytest.approx(ROOF, abs=1e-3)
    assert cells == 36  # 6 m x 6 m at 1 m
    assert [o.cls for o in s.objects] == ["ground", "building"]
    meta = imported.source
    assert meta["units"]["crs"] == "EPSG:32632" and meta["tiles"][0]["kind"] == "las"
    assert len(meta["tiles"][0]["sha256"]) == 64
    truth = imported.terrain.scene
    assert {o.cls for o in truth.objects} == {"ground", "building"}
    top = truth.vertices[:, 2].max() + imported.origin[2]
    assert top == pytest.approx(GROUND_Z + ROOF, abs=1e-3)


def test_isprs_style_pair_takes_its_ground_from_the_second_file(tmp_path):
    pts, cls = field()
    write_points(tmp_path / "all.pcd", pts)
    write_points(tmp_path / "ground.pcd", pts[cls == 2])
    imported = import_terrain([tmp_path / "all.pcd"], Flight(), crs="EPSG:32632",
                              ground=tmp_path / "ground.pcd", cell=1.0)
    height, cells = _building(imported, "object")
    assert cells == 36 and height == pytest.approx(ROOF, abs=1e-3)
    assert [o.cls for o in imported.surfaces.objects] == ["ground", "object"]  # no classes


@pytest.mark.parametrize("suffix", [".tif", ".asc"])
def test_dem_rasters_are_the_bare_earth_at_their_own_cells(tmp_path, suffix):
    height = np.add.outer(np.arange(30.0)[::-1], np.arange(40.0)) * 0.1 + GROUND_Z  # tilted
    height[0, 0] = np.nan  # one nodata cell, filled
    dem = write_dem(tmp_path / f"dem{suffix}", height, cell=2.0)
    imported = import_terrain([dem], Flight())
    s = imported.surfaces
    assert s.step == 2.0 and s.shape == (30, 40)
    expected = height[::-1]  # rasters run north to south, the grid south to north
    got = s.ground
    known = np.isfinite(expected)
    assert np.allclose(got[known], expected[known], atol=1e-9)
    assert got[-1, 0] == pytest.approx(GROUND_Z + 2.9, abs=0.15)  # the nodata cell, filled
    assert not s.measured[-1, 0] and s.measured.sum() == known.sum()
    assert [o.cls for o in s.objects] == ["ground"]


def test_a_tile_in_us_feet_comes_out_in_metres(tmp_path):
    pts, cls = field()
    tile = write_las(tmp_path / "feet.laz", pts, cls, crs=FEET)  # the same numbers, in feet
    imported = import_terrain([tile], Flight(), cell=1.0)
    s = imported.surfaces
    assert imported.source["units"]["horizontal_unit"] == "US survey foot"
    assert imported.source["units"]["horizontal_m_per_unit"] == pytest.approx(US_FOOT)
    xs, _ = s.axes()
    assert xs[-1] - xs[0] == pytest.approx((SIDE - 0.5) * US_FOOT, abs=1.0)
    assert np.median(s.ground) == pytest.approx(GROUND_Z * US_FOOT, abs=1e-3)
    height, _ = _building(imported)
    assert height == pytest.approx(ROOF * US_FOOT, abs=1e-3)


def test_overlapping_tiles_give_the_surfaces_of_the_whole(tmp_path):
    pts, cls = field()
    x = pts[:, 0] - X0
    west, east = x < 40.0, x > 20.0  # 20 m of overlap, the building inside it
    tiles = [write_las(tmp_path / "west.las", pts[west], cls[west]),
             write_las(tmp_path / "east.las", pts[east], cls[east])]
    whole = write_las(tmp_path / "whole.las", pts, cls)
    both, one = (grid_surfaces(read_tiles(t), 1.0) for t in (tiles, [whole]))
    assert both.shape == one.shape and (both.x0, both.y0) == (one.x0, one.y0)
    assert np.array_equal(both.ground, one.ground) and np.array_equal(both.top, one.top)
    assert np.array_equal(both.label, one.label) and both.objects == one.objects


def test_tiles_in_different_crss_are_refused(tmp_path):
    pts, cls = field()
    tiles = [write_las(tmp_path / "a.las", pts, cls),
             write_las(tmp_path / "b.las", pts, cls, crs=FEET)]
    with pytest.raises(ParameterError, match="different CRSs"):
        read_tiles(tiles)


def test_dem_of_only_nodata_is_refused(tmp_path):
    dem = write_dem(tmp_path / "empty.tif", np.full((5, 5), np.nan))
    with pytest.raises(PointFileError, match="every cell is nodata"):
        read_tiles([dem])


def test_no_crs_and_no_crs_flag_is_refused_naming_it(tmp_path):
    pts, cls = field()
    tile = write_las(tmp_path / "nocrs.las", pts, cls, crs=None)
    with pytest.raises(ParameterError, match="no CRS in the file; name the CRS"):
        read_tiles([tile])
    assert read_tiles([tile], crs="EPSG:32632")[0].units.horizontal == "metre"
    with pytest.raises(ParameterError, match="import: crs='EPSG:0'"):
        read_tiles([tile], crs="EPSG:0")


def test_cli_errors_are_one_line_naming_the_flag(tmp_path, capsys):
    pts, cls = field()
    nocrs = write_las(tmp_path / "nocrs.las", pts, cls, crs=None)
    raw = write_las(tmp_path / "raw.las", pts, np.ones(len(pts), np.uint8))
    dem = write_dem(tmp_path / "empty.asc", np.full((5, 5), np.nan))
    degrees = write_las(tmp_path / "degrees.las", pts, cls, crs="EPSG:4326")
    pcd = write_points(tmp_path / "all.pcd", pts)
    cases = [([str(nocrs)], "--crs"), ([str(raw), "--ground-class", "9"], "--ground-class: "),
             ([str(dem)], "nodata"),
             ([str(degrees)], "geographic (degrees)"), ([str(pcd)], "--ground: "),
             ([str(raw), "--ground-class", "1", "--altitude", "-2"], "--altitude -2.0"),
             ([str(raw), "--ground-class", "1", "--region", "1,2,3"], "--region")]
    for args, flag in cases:
        assert main(["simulate", *args, "--out", str(tmp_path / "out")]) == 2
        err = capsys.readouterr().err.strip()
        assert err.startswith("alte simulate: error:") and flag in err and "\n" not in err
    assert not (tmp_path / "out").exists()


def test_region_crops_in_the_tiles_units(tmp_path):
    pts, cls = field()
    tile = write_las(tmp_path / "field.las", pts, cls)
    imported = import_terrain([tile], Flight(), cell=1.0,
                              region=(X0, Y0, X0 + 20.0, Y0 + 20.0))
    assert imported.surfaces.shape == (20, 20)
    assert [o.cls for o in imported.surfaces.objects] == ["ground"]


REAL = realdata_dir() / "als"


@pytest.mark.realdata
def test_real_tiles_bare_earth_meets_the_published_dtm():
    """The drone survey's class-2 bare earth against its team's own DTM (NAVD88, 1 m)."""
    tile, dtm = REAL / "dji_l1_riparian.las", REAL / "dji_l1_riparian_published_dtm.asc"
    if not dtm.is_file():
        pytest.skip(f"real data absent: {dtm}")
    ours = import_terrain([tile], Flight(), cell=1.0)
    theirs = import_terrain([dtm], Flight(), crs="EPSG:6346")
    a, b = ours.surfaces, theirs.surfaces
    assert (a.x0, a.y0, a.shape) == (b.x0, b.y0, b.shape)
    diff = (a.ground - b.ground)[a.measured]
    assert np.median(np.abs(diff)) < 0.1  # where the survey has ground points
    assert {o.cls for o in a.objects} >= {"ground", "tree"}


@pytest.mark.realdata
def test_real_tile_crop_in_its_crs():
    tile = REAL / "ign_lidarhd_farmland.laz"
    if not tile.is_file():
        pytest.skip(f"real data absent: {tile}")
    imported = import_terrain([tile], Flight(), region=(484900, 6632900, 484960, 6632960))
    assert imported.surfaces.shape == (61, 61)
    assert imported.source["units"]["crs"] == "EPSG:2154"
    assert "cropped to the region" in imported.source["tiles"][0]["notes"][-1]
