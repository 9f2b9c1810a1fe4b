"""Flying an imported terrain: a hand-made DEM round trip with errors known by construction,
and the folder every entry point reads."""

import json

import numpy as np
import pytest
from support.tiles import X0, Y0, field, write_dem, write_las

from alte.errors import ParameterError, SimulationError
from alte.lab.studies.experiments import measure
from alte.metrics.options import TruthSettings
from alte.pipeline import open_input, prepare
from alte.sim import VLP16, load_scenario, simulate, write_scenario
from alte.sim.real import Flight, import_terrain, write_imported

PLANE = 250.3  # m: a flat field, off every 0.5 m voxel boundary by 0.3 m


@pytest.fixture(scope="module")
def flat_flight(tmp_path_factory):
    """A 40 m x 40 m flat DEM (1 m cells), imported and flown by a noise-free sensor."""
    where = tmp_path_factory.mktemp("flat")
    dem = write_dem(where / "flat.asc", np.full((40, 40), PLANE))
    imported = import_terrain([dem], Flight())
    sim = simulate(imported.terrain, frames=8, sensor=VLP16(range_sigma=0.0))
    folder = write_scenario(where / "flat", imported.terrain, sim, seed=0, frames=8)
    return prepare(open_input(folder)), imported


def test_dem_round_trip_measures_the_error_known_by_construction(flat_flight):
    data, imported = flat_flight
    datum = imported.origin[2]
    assert datum == 200.0 and imported.source["origin_m"][2] == 200.0
    assert np.allclose(data.cloud[:, 2] + datum, PLANE, atol=1e-4)  # the sensor saw the DEM
    # A 2D map's cells hold the mean height of noise-free points on a plane: no error.
    heights = measure(data, "alte2d", {"max_res": 5, "min_pts": 10}, truth=TruthSettings())
    assert heights.metrics.truth.height_rmse_m == pytest.approx(0.0, abs=1e-4)
    assert heights.metrics.truth.accuracy_mean_m == pytest.approx(0.0, abs=1e-4)
    assert heights.metrics.truth.completeness == pytest.approx(1.0)
    # Octomap's leaves sit where its key grid puts them: each is off the plane by the
    # distance of its centre to 250.3 m, which the truth must measure exactly.
    voxels = measure(data, "octomap", {"resolution": 0.5}, truth=TruthSettings())
    cells = voxels.mapper.cells()
    centres = cells.centers[cells.occupied.astype(bool)]
    assert voxels.metrics.truth.accuracy_mean_m == pytest.approx(
        np.mean(np.abs(centres[:, 2] + datum - PLANE)), abs=1e-4)
    assert imported.source["altitude_m"] == 10.0  # the thesis' landing altitude


def test_imported_folder_is_a_terrain_every_entry_point_reads(tmp_path):
    pts, cls = field()
    tile = write_las(tmp_path / "field.laz", pts, cls)
    imported = import_terrain([tile], Flight(mission="navigation"), name="field")
    folder = write_imported(imported, tmp_path / "data", frames=5)
    assert folder.name == "field-5f"
    meta = json.loads((folder / "scenario.json").read_text())
    assert meta["kind"] == "real" and meta["case"] == "nav"
    assert meta["source"]["origin_m"] == [X0, Y0, 200.0]
    assert meta["source"]["units"]["crs"] == "EPSG:32632"
    assert {o["class"] for o in meta["objects"]} == {"ground", "building"}
    assert set(meta["files"]) >= {"bare_earth.npz", "ground_truth.ply"}
    scenario = load_scenario(folder)
    assert scenario.case == "nav" and len(scenario.ground_truth.objects) == 2
    run = measure(prepare(open_input(folder)), "octomap", {"resolution": 1.0},
                  truth=TruthSettings())
    assert run.metrics.truth.completeness_by_class["building"] > 0.3
    assert run.metrics.truth.completeness_seen > 0.9
    with pytest.raises(SimulationError, match=r"exists .*force=True replaces it"):
        write_imported(imported, tmp_path / "data", frames=5)


def test_flight_climbs_over_objects_and_follows_the_ground(tmp_path):
    pts, cls = field()
    tile = write_las(tmp_path / "field.las", pts, cls)
    imported = import_terrain([tile], Flight(altitude=6.0, clearance=4.0), cell=1.0)
    heights = np.asarray(imported.terrain.spec.platform.heights) + imported.origin[2]
    # 6 m above the ground, 4 m above the 8 m roof wherever the roof is within reach.
    assert heights.min() == pytest.approx(250.0 + 6.0, abs=0.3)
    assert heights.max() == pytest.approx(250.0 + 8.0 + 4.0, abs=0.3)


def test_the_trade_off_grid_runs_on_an_imported_terrain(tmp_path):
    """A sweep names the imported terrain like a built-in one: other seeds and scan
    counts of its mission are flown from the folder, every map is measured on its truth."""
    from alte.lab.studies.sweep import parse_spec, run_sweep
    from alte.lab.studies.tradeoff.grid import tradeoff_table

    pts, cls = field()
    tile = write_las(tmp_path / "field.laz", pts, cls)
    data = tmp_path / "data"
    write_imported(import_terrain([tile], Flight(), name="field_lan"), data)
    spec = parse_spec({"terrains": ["field_lan"], "frames": 4, "seeds": [0, 1],
                       "data_dir": str(data), "obstacles": True,
                       "mappers": {"quadtree": {"grid": {"max_points": [25, 200]}}}}, "test")
    result = run_sweep(spec, scheduler="serial", output=tmp_path / "out", progress=False)
    table = tradeoff_table(result.table)
    assert len(table) == 4 and set(table["case"]) == {"lan"}
    assert table["height_rmse_m"].notna().all() and (table["height_rmse_m"] < 1.0).all()
    assert (data / "field_lan-4f-s1" / "scenario.json").is_file()
    with pytest.raises(ParameterError, match=r"unknown terrain.*imported into"):
        parse_spec({"terrains": ["moon"], "data_dir": str(data),
                    "mappers": {"quadtree": {"grid": {"max_points": [25]}}}}, "test")
