"""Chapter 6 (alte.lab.studies.realdata): locating the data, the map-based ground filter and its
scores, the 3D maps of the real scans, and the clean skip when the folder is absent."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from alte.errors import MetricsError, ParameterError, PointFileError
from alte.io import write_points
from alte.lab.studies import realdata
from alte.lab.studies.realdata import figures as realdata_plot
from alte.mappers import make_mapper
from alte.paths import realdata_dir

REALDATA = realdata_dir()
UTM = np.array([513_000.0, 5_404_000.0, 0.0])
ALTE2D = {"kappa": 5.0, "max_res": 7, "min_pts": 10}
QUADTREE = {"max_points": 25, "max_depth": 10}


def _terrain(seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """A sloped 100 m square at ~1 pt/m^2 with a 10 m building (8 m) and a 6 m tree block."""
    rng = np.random.default_rng(seed)
    xy = np.stack(np.meshgrid(np.arange(100.0), np.arange(100.0)), -1).reshape(-1, 2)
    xy += rng.uniform(-0.3, 0.3, xy.shape)
    z = 300.0 + 0.05 * xy[:, 0] + 0.02 * xy[:, 1] + rng.normal(0, 0.05, len(xy))
    building = (np.abs(xy[:, 0] - 30) < 5) & (np.abs(xy[:, 1] - 30) < 5)
    trees = (np.abs(xy[:, 0] - 70) < 3) & (np.abs(xy[:, 1] - 60) < 3)
    z[building] += 8.0
    z[trees] += rng.uniform(3, 6, int(trees.sum()))
    return np.column_stack([xy, z]), ~(building | trees)


@pytest.fixture
def fake_root(tmp_path: Path) -> Path:
    """A real-data folder holding one synthetic ISPRS-like sample (in UTM, as stored)."""
    points, ground = _terrain()
    folder = tmp_path / "realdata" / "isprs_terrain"
    write_points(folder / "samp21-utm.pcd", points + UTM)
    write_points(folder / "samp21-utm-ground.pcd", points[ground] + UTM)
    return tmp_path / "realdata"


# ------------------------------------------------------------------ locating / skipping


def test_default_dir_is_next_to_the_repository() -> None:
    repo = Path(realdata.__file__).resolve().parents[4]
    assert realdata.default_dir() == repo.parent / "shared" / "realdata"


def test_absent_folder_skips_everything(tmp_path: Path) -> None:
    data = realdata.locate(tmp_path / "nowhere")
    assert not data.available
    assert "nowhere" in data.reason and data.describe().startswith("SKIPPED")
    assert realdata.ground_runs(data, None, {"alte2d": ALTE2D}) == []
    assert realdata.isprs_samples(data) == ()
    assert realdata.scan_dataset(data) is None and realdata.vlp16_dataset(data) is None
    assert realdata.map_runs(None, {"octomap": {}}) == []
    assert realdata.ground_table([]).empty and realdata.map_table([]).empty
    assert realdata_plot.ground_figure([]) is None
    assert realdata_plot.save_figure(None, tmp_path, "fig") is None
    assert realdata_plot.show_maps([], tmp_path, "maps", caption=realdata_plot.SCAN_MAPS) is None
    assert realdata.write_csv(pd.DataFrame(), tmp_path, "table") is None
    assert realdata.results(data, table=pd.DataFrame({"a": [1]})) == {"skipped": data.reason}
    assert not list(tmp_path.iterdir())
    with pytest.raises(ParameterError, match=r"real data unavailable: .*nowhere"):
        data.file("octomap_scan", "scan.dat.bz2")


def test_present_folder_and_results(fake_root: Path, tmp_path: Path) -> None:
    data = realdata.locate(str(fake_root))
    assert data.available and data.root == fake_root.resolve()
    assert data.describe() == f"real data: {fake_root.resolve()}"
    table = pd.DataFrame({"a": [1.5, 2.0]})
    out = realdata.results(data, table=table, n=3)
    assert out == {"realdata_dir": str(fake_root.resolve()), "table": [{"a": 1.5}, {"a": 2.0}],
                   "n": 3}
    path = realdata.write_csv(table, tmp_path / "tables", "table_6_9")
    assert path.name == "table_6_9.csv" and pd.read_csv(path).equals(table)


def test_every_sample_present_is_filtered(fake_root: Path) -> None:
    data = realdata.locate(fake_root)
    folder = fake_root / "isprs_terrain"
    points, ground = _terrain(seed=1)
    write_points(folder / "samp52-utm.pcd", points + UTM)
    write_points(folder / "samp52-utm-ground.pcd", points[ground] + UTM)
    write_points(folder / "samp61-utm.pcd", points + UTM)  # no reference: not a sample
    assert realdata.isprs_samples(data) == ("samp21", "samp52")
    runs = realdata.ground_runs(data, None, {}, progress=False)
    assert [r.sample for r in runs] == ["samp21", "samp52"]


def test_missing_file_in_present_folder_names_it(fake_root: Path) -> None:
    data = realdata.locate(fake_root)
    with pytest.raises(PointFileError, match=r"samp11-utm\.pcd"):
        realdata.isprs_sample(data, "samp11")
    with pytest.raises(PointFileError, match=r"scan\.dat\.bz2"):
        realdata.scan_dataset(data)
    with pytest.raises(ParameterError, match=r"samples \['samp99'\] unknown; samples present "
                       r"in .*isprs_terrain: \['samp21'\]"):
        realdata.ground_runs(data, ["samp99"], {})
    with pytest.raises(ParameterError, match="frames=0"):
        realdata.vlp16_dataset(data, frames=0)


# ------------------------------------------------------------------ ground filter pieces


def test_reference_labels_match_within_tolerance() -> None:
    pts = np.array([[0.0, 0, 0], [1, 1, 1], [2, 2, 2]])
    sub = np.array([[1.0005, 1, 1], [2.1, 2, 2]])
    assert realdata.reference_labels(pts, sub).tolist() == [False, True, False]
    assert realdata.reference_labels(pts, sub, tolerance=0.2).tolist() == [False, True, True]
    assert not realdata.reference_labels(pts, np.empty((0, 3))).any()
    with pytest.raises(MetricsError, match=r"subset \(2, 2\)"):
        realdata.reference_labels(pts, sub[:, :2])


def test_opening_keeps_a_slope_and_cuts_narrow_objects() -> None:
    points, ground = _terrain()
    surface = realdata.opened_surface(points, points[:, 2], step=1.0, window=20.0)
    # on sloped ground, half a window or more from the edge, the surface is the local
    # lowest point (noise + slope across a pixel); nearer an uphill edge it sags
    inner = ground & (np.abs(points[:, :2] - 49.5) < 39).all(axis=1)
    assert np.abs(points[inner, 2] - surface[inner]).max() < 0.35
    assert np.abs(points[ground, 2] - surface[ground]).max() < 0.05 * 10 + 0.02 * 10 + 0.35
    # on the 10 m building and the trees it is the ground below them, not the roof
    assert (points[~ground, 2] - surface[~ground]).min() > 2.5
    narrow = realdata.opened_surface(points, points[:, 2], step=1.0, window=5.0)
    assert (points[~ground, 2] - narrow[~ground] < 1.0).mean() > 0.5  # window < building


def test_opening_ignores_unknown_heights_and_checks_parameters() -> None:
    xy = np.array([[0.0, 0], [0.5, 0.5], [10, 10]])
    surface = realdata.opened_surface(xy, np.array([1.0, np.nan, np.nan]), 1.0, 3.0)
    assert surface[0] == 1.0 and surface[1] == 1.0 and np.isnan(surface[2])
    assert realdata.opened_surface(np.empty((0, 2)), np.empty(0)).shape == (0,)
    for step, window in ((0.0, 5.0), (1.0, 0.5), (np.nan, 5.0)):
        with pytest.raises(ParameterError, match=r"step=.* window="):
            realdata.opened_surface(xy, xy[:, 0], step, window)


def test_classify_ground_and_map_heights() -> None:
    pts = np.array([[0.0, 0, 1.0], [0, 0, 1.6], [0, 0, 0.2], [0, 0, 5.0]])
    surface = np.array([1.0, 1.0, 1.0, np.nan])
    assert realdata.classify_ground(pts, surface, 0.8).tolist() == [True, True, True, False]
    assert realdata.classify_ground(pts, surface, 0.5).tolist() == [True, False, False, False]
    with pytest.raises(ParameterError, match="tolerance=-1"):
        realdata.classify_ground(pts, surface, -1)
    mapper = make_mapper("alte2d", kappa=1e-6, max_res=1, min_pts=1)
    mapper.build(np.array([[0.0, 0, 1], [1, 1, 3], [0.9, 0.1, 2], [0.8, 0.2, 2]]))
    heights = realdata.map_heights(mapper.cells(), np.array([[0.1, 0.1], [0.9, 0.9], [0.1, 0.9],
                                                            [5, 5]]))
    np.testing.assert_allclose(heights[:2], [1.0, 3.0])
    assert np.isnan(heights[2:]).all()  # an unknown (empty) leaf and outside the map


def test_ground_errors_as_sithole_vosselman() -> None:
    ref = np.array([True] * 6 + [False] * 4)
    pred = np.array([True] * 4 + [False] * 2 + [True] + [False] * 3)
    out = realdata.ground_errors(pred, ref)
    assert out["type_i_pct"] == pytest.approx(100 * 2 / 6)
    assert out["type_ii_pct"] == pytest.approx(100 * 1 / 4)
    assert out["total_pct"] == pytest.approx(100 * 3 / 10)
    assert (out["ground_rejected"], out["objects_accepted"]) == (2, 1)
    assert np.isnan(realdata.ground_errors(pred[:6], ref[:6])["type_ii_pct"])
    with pytest.raises(MetricsError, match=r"predicted \(3,\) and reference \(10,\)"):
        realdata.ground_errors(pred[:3], ref)


def test_outcome_codes() -> None:
    codes = realdata_plot.outcomes(np.array([1, 0, 0, 1], bool), np.array([1, 0, 1, 0], bool))
    assert codes.tolist() == [0, 1, 2, 3]


# ------------------------------------------------------------------ pipeline on a fake sample


def test_ground_runs_on_a_synthetic_sample(fake_root: Path, tmp_path: Path) -> None:
    data = realdata.locate(fake_root)
    sample = realdata.isprs_sample(data, "samp21")
    np.testing.assert_array_equal(sample.origin, UTM)  # local_origin of the stored cloud
    np.testing.assert_array_equal(sample.reference, _terrain()[1])
    runs = realdata.ground_runs(data, ["samp21"], {"alte2d": ALTE2D, "quadtree": QUADTREE},
                                progress=False)
    table = realdata.ground_table(runs)
    assert table["filter"].tolist() == [realdata.BASELINE, "alte2d", "quadtree"]
    assert table.loc[0, "basis_functions"] == 0 and (table["basis_functions"][1:] > 0).all()
    assert (table["total_pct"] < 3.0).all(), table
    assert (table["type_ii_pct"] < 5.0).all(), table
    assert table.loc[1, "params"] == "kappa=5.0, max_res=7, min_pts=10"
    plot = realdata_plot.ground_figure(runs)
    assert plot is not None and len(plot.figure.axes) == 3
    path = realdata_plot.save_figure(plot, tmp_path, "ground")
    assert path is not None and path.read_bytes()[:4] == b"\x89PNG"
    assert path.with_suffix(".json").is_file()  # its caption beside it


# ------------------------------------------------------------------ the real recordings


def _real() -> realdata.RealData:
    data = realdata.locate(REALDATA)
    if not data.available:
        pytest.skip("../shared/realdata absent")
    return data


@pytest.mark.realdata
def test_isprs_reference_labels_and_errors() -> None:
    data = _real()
    sample = realdata.isprs_sample(data, "samp21")
    assert len(sample.points) == 12960 and sample.reference.sum() == 10085
    assert np.abs(sample.points[:, :2]).max() < 1000  # UTM offset removed
    runs = realdata.ground_runs(data, ["samp21", "samp31"], {"alte2d": ALTE2D}, progress=False)
    table = realdata.ground_table(runs).set_index(["sample", "filter"])
    # the filters Sithole & Vosselman compared made 2-9 % total error on these samples
    assert table["total_pct"].between(0.5, 10).all(), table
    row = table.loc[("samp21", "alte2d")]
    assert row["ground_rejected"] + row["objects_accepted"] == pytest.approx(
        row["total_pct"] * 12960 / 100)


@pytest.mark.realdata
def test_octomap_scan_and_vlp16_bag_are_mapped() -> None:
    data = _real()
    mappers = {"octomap": {"resolution": 10.0},
               "alte3d": {"max_res": 6, "min_pts": 5, "min_pts_split": 10,
                          "occupancy_level": 6}}
    vlp = realdata.vlp16_dataset(data)
    info = realdata.dataset_summary(vlp)
    assert info["frames"] == 4 and info["points"] == info["raw_points"] > 40_000
    assert len(realdata.vlp16_dataset(data, frames=2)) == 2
    table = realdata.map_table(realdata.map_runs(vlp, mappers, progress=False))
    assert table["mapper"].tolist() == ["octomap", "alte3d"]
    assert (table["basis_functions"] > table["occupied_cells"]).all()
    assert (table["occupied_cells"] > 0).all() and (table["memory_bytes"] > 0).all()
    assert (table["hd_m"] >= table["mhd_m"]).all() and (table["mhd_m"] < 0.5).all()
    scan = realdata.scan_dataset(data)
    assert len(scan.cloud) == 88206 and scan.frame(0).origin.tolist() == [0, 0, 0]
    np.testing.assert_array_equal(scan.bounds().lo, scan.cloud.min(axis=0))
