"""End-to-end through the written bags: simulation and registration agree with the mesh."""

import dataclasses

import numpy as np
import pytest

from alte.io import read_frames
from alte.registration import register
from alte.sim import TERRAINS, get_terrain, load_scenario, mesh_distance, simulate, write_scenario

SIM = [n for n in TERRAINS if n.startswith("sim_")]
EXP = [n for n in TERRAINS if n.startswith("exp_")]
SIGMA = 0.03


def _cloud(folder, voxel=None, **kw):
    scenario = load_scenario(folder)
    frames = read_frames(scenario.bag)
    reg = register(frames.frames, frames.mount, voxel=voxel, crop_box=scenario.crop_box, **kw)
    return scenario, frames, reg


@pytest.mark.parametrize("name", SIM)
def test_every_simulated_return_lies_on_the_mesh_within_4_sigma(small_terrain, name):
    scenario, frames, reg = _cloud(small_terrain(name))
    assert len(frames.frames) == 40
    dist = mesh_distance(reg.points, scenario.ground_truth)
    assert dist.max() <= 4 * SIGMA + 1e-3
    assert 0.3 * SIGMA < np.mean(dist) < SIGMA  # the noise is there, mostly along the beams


@pytest.mark.parametrize("name", EXP)
def test_exp_returns_lie_on_the_mesh_without_desync_and_mocap_noise(tmp_path, name):
    terrain = get_terrain(name)
    cart = dataclasses.replace(terrain.spec.platform, time_offset_s=0.0, jitter_s=0.0,
                               position_sigma=0.0, attitude_sigma_deg=0.0)
    terrain = dataclasses.replace(terrain, spec=dataclasses.replace(terrain.spec, platform=cart))
    folder = write_scenario(tmp_path / name, terrain, simulate(terrain, frames=20), seed=0,
                            frames=20)
    scenario, _, reg = _cloud(folder)
    # 100 Hz motion capture interpolated at the scan stamp: a few mm on top of the noise
    assert mesh_distance(reg.points, scenario.ground_truth).max() <= 4 * SIGMA + 0.005


@pytest.mark.parametrize("name", SIM)
def test_registered_sim_cloud_is_within_mhd_5cm_of_its_mesh(small_terrain, name):
    scenario, _, reg = _cloud(small_terrain(name), voxel=get_terrain(name).spec.registration_voxel)
    assert mesh_distance(reg.points, scenario.ground_truth).mean() < 0.05


#: Scans of the desync test: 70 show it as 140 did (MHD 2.8 times the calm terrain's, 2.9
#: with 140; the filter halves it); 40 no longer do (2.2).
DESYNC_FRAMES = 70


def test_exp_nav_2_shows_desync_and_the_manoeuvre_filter_reduces_it(small_terrain):
    """exp_nav_2's desynchronised poses double its MHD over exp_nav_1's; dropping the
    fast-turning scans (max_rate) takes most of it back."""
    voxel = get_terrain("exp_nav_2").spec.registration_voxel
    scenario, _, reg = _cloud(small_terrain("exp_nav_2", DESYNC_FRAMES), voxel=voxel)
    mhd = mesh_distance(reg.points, scenario.ground_truth).mean()
    calm_scenario, _, calm = _cloud(small_terrain("exp_nav_1", DESYNC_FRAMES), voxel=voxel)
    calm_mhd = mesh_distance(calm.points, calm_scenario.ground_truth).mean()
    _, _, kept = _cloud(small_terrain("exp_nav_2", DESYNC_FRAMES), voxel=voxel, max_rate=0.5)
    filtered = mesh_distance(kept.points, scenario.ground_truth).mean()
    assert mhd > 2.5 * calm_mhd
    assert 0 < kept.counts.frames_dropped_rate < DESYNC_FRAMES
    assert filtered < 0.7 * mhd


def test_the_sim_lan_2_roof_ridge_is_never_scanned(small_terrain):
    scenario, _, reg = _cloud(small_terrain("sim_lan_2"))
    altitude = get_terrain("sim_lan_2").spec.platform.altitude
    roof = next(i for i, o in enumerate(scenario.ground_truth.objects) if o.name == "house_roof")
    ridge = scenario.ground_truth.vertices[scenario.ground_truth.triangles[
        scenario.ground_truth.object_ids == roof]].max()
    assert ridge > altitude > reg.points[:, 2].max()


@pytest.mark.slow
@pytest.mark.parametrize(("name", "frames", "points"), [("sim_nav_1", 569, 381_187),
                                                        ("sim_lan_2", 508, 439_032)])
def test_full_missions_match_the_thesis_tables(tmp_path, name, frames, points):
    from alte.sim import ensure_terrain

    scenario, read, reg = _cloud(ensure_terrain(name, tmp_path),
                                 voxel=get_terrain(name).spec.registration_voxel)
    assert len(read.frames) == frames == scenario.metadata["counts"]["frames"]
    assert 0.9 * points < len(reg.points) < 1.1 * points
    assert mesh_distance(reg.points, scenario.ground_truth).mean() < 0.05


@pytest.mark.slow
def test_full_exp_nav_2_mhd_exceeds_the_sim_bound(tmp_path):
    from alte.sim import ensure_terrain

    voxel = get_terrain("exp_nav_2").spec.registration_voxel
    scenario, _, reg = _cloud(ensure_terrain("exp_nav_2", tmp_path), voxel=voxel)
    assert mesh_distance(reg.points, scenario.ground_truth).mean() > 0.05
