"""``alte ground``: tiles in, classified LAS/LAZ out with provenance; bad input named in the
command's terms; every shared real tile (cropped) classified."""

from __future__ import annotations

import json
from pathlib import Path

import laspy
import numpy as np
import pytest
from ground.test_filters import slope_with_objects

from alte.cli import main
from alte.io import write_points
from alte.io.points.tiles import read_provenance
from alte.paths import realdata_dir

REALDATA = realdata_dir()
UTM32 = "EPSG:32632"


@pytest.fixture(scope="module")
def scene(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, np.ndarray]:
    points, truth = slope_with_objects(size=40.0)
    path = tmp_path_factory.mktemp("ground") / "scene.pcd"
    write_points(path, points + np.array([513_000.0, 5_404_000.0, 0.0]))
    return path, truth


def _las(path: Path, points: np.ndarray, crs: str | None) -> Path:
    header = laspy.LasHeader(point_format=6, version="1.4")
    header.offsets, header.scales = np.floor(points.min(axis=0)), np.full(3, 0.001)
    if crs is not None:
        import pyproj

        header.add_crs(pyproj.CRS.from_user_input(crs))
    las = laspy.LasData(header)
    las.x, las.y, las.z = points.T
    las.intensity = np.arange(len(points), dtype=np.uint16)
    las.write(path)
    return path


def test_a_point_file_becomes_classified_laz(scene: tuple[Path, np.ndarray], tmp_path: Path,
                                             capsys: pytest.CaptureFixture[str]) -> None:
    path, truth = scene
    out = tmp_path / "scene.laz"
    assert main(["ground", str(path), "--out", str(out), "--crs", UTM32, "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    las = laspy.read(out)
    classes = np.asarray(las.classification)
    assert set(np.unique(classes)) == {1, 2} and len(classes) == len(truth)
    assert np.mean((classes == 2) == truth) > 0.95
    assert summary["ground_share"] == pytest.approx(np.mean(classes == 2), abs=1e-4)
    assert summary["method"] == "smrf" and summary["points_per_s"] > 0
    assert las.header.parse_crs().to_epsg() == 32632
    provenance = read_provenance(out)
    assert provenance is not None and provenance["method"] == "smrf"
    assert provenance["settings"] == {"cell": 1.0, "window": 18.0, "slope": 0.10,
                                      "threshold": 0.5, "scalar": 1.25}
    assert "Pingel" in str(provenance["source"])
    # an existing output is kept unless --force
    assert main(["ground", str(path), "--out", str(out)]) == 2
    assert "already exists" in capsys.readouterr().err
    assert main(["ground", str(path), "--out", str(out), "--force", "--method", "morph",
                 "--set", "window=30"]) == 0
    assert read_provenance(out)["settings"]["window"] == 30.0  # type: ignore[index]


def test_a_las_tile_keeps_its_fields_and_crs(tmp_path: Path) -> None:
    points, _ = slope_with_objects(size=30.0)
    tile = _las(tmp_path / "tile.las", points + np.array([500_000.0, 4_000_000.0, 0.0]), UTM32)
    out = tmp_path / "out.las"
    assert main(["ground", str(tile), "--out", str(out), "--method", "csf"]) == 0
    las = laspy.read(out)
    np.testing.assert_array_equal(las.intensity, np.arange(len(points)))
    assert las.header.parse_crs().to_epsg() == 32632
    assert read_provenance(out)["method"] == "csf"  # type: ignore[index]


@pytest.mark.parametrize(("case", "extra", "match"), [
    ("no_crs", [], r"its LAS header names no coordinate reference system.*--crs EPSG:CODE"),
    ("degrees", [], r"coordinates in degrees \(WGS 84\); reproject"),
    ("feet", [], r"coordinates in US survey foot .*reproject"),
    ("both_crs", ["--crs", UTM32], r"--crs EPSG:32632: .* already names its CRS"),
    ("bad_crs", ["--crs", "EPSG:0"], r"--crs 'EPSG:0': not a coordinate reference system"),
    ("dem", [], r"a raster \(\.asc\), a DEM or an image, not a point cloud"),
    ("dem_points", [], r"regular 1 m grid, one point per cell: a raster DEM"),
    ("empty", [], r"no points"),
    ("bad_set", ["--set", "slope=-2"], r"--set: ground smrf: slope=-2.0 out of range"),
    ("bad_key", ["--set", "slop=2"], r"--set: ground smrf: unknown parameter\(s\) slop"),
    ("no_equals", ["--set", "slope"], r"--set 'slope': expected KEY=VALUE"),
    ("bad_out", [], r"--out .*out\.txt: the output is LAS or LAZ"),
])
def test_bad_input_is_named(case: str, extra: list[str], match: str, tmp_path: Path,
                            capsys: pytest.CaptureFixture[str]) -> None:
    points, _ = slope_with_objects(size=15.0)
    points = points + np.array([500_000.0, 4_000_000.0, 0.0])
    crs = {"no_crs": None, "bad_crs": None, "degrees": "EPSG:4326",
           "feet": "EPSG:2264"}.get(case, UTM32)
    source = _las(tmp_path / "in.las", points if case != "degrees" else points / 1e5, crs)
    if case == "dem":
        source = tmp_path / "dtm.asc"
        source.write_text("ncols 2\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2\n3 4\n")
    elif case == "dem_points":
        gx, gy = np.meshgrid(np.arange(30.0), np.arange(20.0))
        source = tmp_path / "dem.xyz"
        write_points(source, np.column_stack([gx.ravel(), gy.ravel(), gx.ravel() * 0.1]))
    elif case == "empty":
        source = tmp_path / "empty.las"
        laspy.LasData(laspy.LasHeader(point_format=6, version="1.4")).write(source)
    out = tmp_path / ("out.txt" if case == "bad_out" else "out.laz")
    assert main(["ground", str(source), "--out", str(out), *extra]) == 2
    err = capsys.readouterr().err
    assert err.startswith("alte ground: error: ") and len(err.strip().splitlines()) == 1
    assert __import__("re").search(match, err), err
    assert not out.exists()


def _real_tiles() -> list[Path]:
    if not REALDATA.is_dir():
        return []
    return sorted([*REALDATA.glob("als/**/*.la[sz]"), *REALDATA.glob("isprs_terrain/*-utm.pcd")])


@pytest.mark.realdata
@pytest.mark.skipif(not REALDATA.is_dir(), reason="../shared/realdata absent")
@pytest.mark.parametrize("tile", _real_tiles(), ids=lambda p: p.name)
def test_every_shared_tile_is_classified(tile: Path, tmp_path: Path) -> None:
    """Each real tile, a LAS/LAZ cropped to a 30 m square at its centre (the whole tiles:
    the bench): its format, header and CRS are what is read, wider than the ground
    filter's 18 m window, with ground and objects in it."""
    if tile.suffix == ".pcd":
        source = tile
    else:
        las = laspy.read(tile)
        centre = np.array([np.median(las.x), np.median(las.y)])
        keep = (np.abs(las.x - centre[0]) < 15) & (np.abs(las.y - centre[1]) < 15)
        source = tmp_path / tile.name
        las[np.asarray(keep)].write(source)
    out = tmp_path / "out.laz"
    assert main(["ground", str(source), "--out", str(out)]) == 0
    classes = np.asarray(laspy.read(out).classification)
    assert set(np.unique(classes)) <= {1, 2}
    assert np.mean(classes == 2) > 0.05  # (the farmland's centre is a bare field: all 2)
