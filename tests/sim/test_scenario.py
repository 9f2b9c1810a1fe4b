"""Terrain folders: contents, determinism, cache reuse/invalidation, errors."""

import json

import numpy as np
import pytest

from alte.errors import ParameterError, SimulationError
from alte.sim import TERRAINS, ensure_terrain, get_terrain, load_scenario, simulate
from alte.sim.groundtruth import GROUND_TRUTH_FILE
from alte.sim.mission import scan_indices
from alte.sim.scenario import terrain_folder, update_terrain


def _bytes(folder):
    return {p.relative_to(folder).as_posix(): p.read_bytes()
            for p in sorted(folder.rglob("*")) if p.is_file()}


def test_eight_terrains_with_thesis_frame_counts():
    assert list(TERRAINS) == ["sim_nav_1", "sim_nav_2", "sim_lan_1", "sim_lan_2",
                              "exp_nav_1", "exp_nav_2", "exp_lan_1", "exp_lan_2"]
    assert get_terrain("sim_nav_1").spec.frames == 569
    assert get_terrain("sim_lan_2").spec.frames == 508
    for name in TERRAINS:
        spec = get_terrain(name).spec
        assert spec.case == name.split("_")[1] and spec.kind == name.split("_")[0]


def test_folder_contents_and_metadata(small_terrain):
    folder = small_terrain("exp_lan_1", 10)
    meta = json.loads((folder / "scenario.json").read_text())
    assert {"bag", "ground_truth.ply", "scenario.json"} <= {p.name for p in folder.iterdir()}
    assert meta["seed"] == 0 and meta["frames_requested"] == 10 and meta["case"] == "lan"
    assert meta["counts"]["frames"] == 10 and meta["counts"]["poses"] > 100 * 39  # 100 Hz mocap
    assert meta["control_volume"] == [0.0, 0.0, -0.2, 8.0, 6.0, 2.5]
    assert set(meta["files"]) == {"bag/bag.db3", "bag/metadata.yaml", "ground_truth.ply"}
    scenario = load_scenario(folder)
    assert scenario.case == "lan" and scenario.registration_voxel == 0.03
    assert np.allclose(scenario.mount.quaternion, get_terrain("exp_lan_1").spec.mount.quaternion)
    assert {o.cls for o in scenario.ground_truth.objects} >= {"car", "debris", "ground", "room"}


def test_same_seed_same_bytes_other_seed_other_bytes(tmp_path):
    a = ensure_terrain("exp_nav_2", tmp_path / "a", seed=3, frames=6)
    b = ensure_terrain("exp_nav_2", tmp_path / "b", seed=3, frames=6)
    c = ensure_terrain("exp_nav_2", tmp_path / "c", seed=4, frames=6)
    assert _bytes(a) == _bytes(b)
    assert _bytes(a)["bag/bag.db3"] != _bytes(c)["bag/bag.db3"]
    assert _bytes(a)["ground_truth.ply"] == _bytes(c)["ground_truth.ply"]


def test_cache_is_reused_only_when_spec_seed_and_files_match(tmp_path):
    folder, made = update_terrain("sim_lan_1", tmp_path, seed=0, frames=4)
    assert made
    stamp = (folder / "bag" / "bag.db3").stat().st_mtime_ns
    assert update_terrain("sim_lan_1", tmp_path, seed=0, frames=4) == (folder, False)
    assert (folder / "bag" / "bag.db3").stat().st_mtime_ns == stamp
    assert update_terrain("sim_lan_1", tmp_path, seed=1, frames=4)[1]  # other seed
    other, made = update_terrain("sim_lan_1", tmp_path, seed=1, frames=5)  # other mission
    assert made and other == terrain_folder(tmp_path, "sim_lan_1", 5, 1) != folder
    assert folder.is_dir()  # a reduced mission never replaces another one
    with open(other / "bag" / "bag.db3", "r+b") as fh:  # damaged after the fact
        fh.seek(200)
        fh.write(b"\xff\xff")
    assert update_terrain("sim_lan_1", tmp_path, seed=1, frames=5)[1]
    assert update_terrain("sim_lan_1", tmp_path, seed=1, frames=5, force=True)[1]
    assert not list(tmp_path.glob(".*part*"))  # no temporary folders left behind


def test_a_file_changed_after_a_check_is_found(tmp_path):
    folder, _ = update_terrain("sim_lan_1", tmp_path, seed=0, frames=3)
    assert update_terrain("sim_lan_1", tmp_path, seed=0, frames=3) == (folder, False)
    assert update_terrain("sim_lan_1", tmp_path, seed=0, frames=3) == (folder, False)  # memo
    (folder / GROUND_TRUTH_FILE).write_bytes(b"not the mesh")  # after the checks
    assert update_terrain("sim_lan_1", tmp_path, seed=0, frames=3)[1]


def test_subset_scans_equal_the_full_missions_scans():
    terrain = get_terrain("exp_nav_1")
    few, more = simulate(terrain, frames=3), simulate(terrain, frames=5)
    assert np.array_equal(few.scan_index, [0, 150, 299]) and 150 in more.scan_index
    for i, idx in enumerate(few.scan_index):
        j = int(np.flatnonzero(more.scan_index == idx)[0])
        assert np.array_equal(few.scans[i], more.scans[j]) and few.stamps[i] == more.stamps[j]


def test_errors(tmp_path):
    with pytest.raises(SimulationError, match="unknown terrain 'moon'; valid: sim_nav_1"):
        ensure_terrain("moon", tmp_path)
    with pytest.raises(ParameterError, match="frames=0"):
        scan_indices(10, 0)
    with pytest.raises(ParameterError, match="exceeds the mission's 10 scans"):
        scan_indices(10, 11)
    with pytest.raises(ParameterError, match="seed=-1"):
        simulate(get_terrain("sim_lan_1"), seed=-1, frames=1)
    mine = terrain_folder(tmp_path, "sim_lan_1", 2)
    mine.mkdir()
    (mine / "mine.txt").write_text("user data")
    with pytest.raises(SimulationError, match="not a simulated terrain folder"):
        ensure_terrain("sim_lan_1", tmp_path, frames=2)


def test_load_scenario_errors(tmp_path, small_terrain):
    with pytest.raises(SimulationError, match=r"no scenario\.json"):
        load_scenario(tmp_path)
    (tmp_path / "scenario.json").write_text("{oops")
    with pytest.raises(SimulationError, match="not valid JSON"):
        load_scenario(tmp_path)
    (tmp_path / "scenario.json").write_text("{}")
    with pytest.raises(SimulationError, match="missing keys"):
        load_scenario(tmp_path)
    meta = json.loads((small_terrain("sim_lan_2", 10) / "scenario.json").read_text())
    (tmp_path / "scenario.json").write_text(json.dumps(meta))
    with pytest.raises(SimulationError, match="bag folder 'bag' is missing"):
        load_scenario(tmp_path)
    (tmp_path / "bag").mkdir()
    with pytest.raises(SimulationError, match="cannot read ground truth"):
        load_scenario(tmp_path)
