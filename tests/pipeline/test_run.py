"""Tests for the one path from an input to a map: streamed or prepared, every policy."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from alte.errors import ParameterError
from alte.io.points.pointfiles import write_points
from alte.mappers import Feed
from alte.mappers.domain import Domain
from alte.pipeline import (
    DomainChoice,
    DomainPolicy,
    FrameSettings,
    MapSettings,
    open_input,
    prepare,
    run,
)

PARAMS = {"quadtree": {"max_points": 50}, "alte2d": {"max_res": 5},
          "alte3d": {"max_res": 5, "min_pts": 5, "min_pts_split": 10},
          "octomap": {"resolution": 1.0}}


def _same_map(a, b) -> None:
    assert a.mapper.basis_functions == b.mapper.basis_functions
    ca, cb = a.mapper.cells(), b.mapper.cells()
    np.testing.assert_array_equal(ca.centers, cb.centers)
    np.testing.assert_array_equal(ca.occupied, cb.occupied)


@pytest.mark.parametrize("mapper", sorted(PARAMS))
def test_streamed_run_equals_the_prepared_one(terrain: Path, tmp_path: Path, mapper: str) -> None:
    spec = MapSettings(mapper, PARAMS[mapper])
    live = run(terrain, spec, FrameSettings(frames=3))
    prepared = run(prepare(open_input(terrain), FrameSettings(frames=3)), spec)
    cached = run(terrain, spec, FrameSettings(frames=3), cache=tmp_path)
    _same_map(live, prepared)
    _same_map(live, cached)
    assert live.info.domain == prepared.info.domain
    assert len(live.log.stamps) == 3 and live.log.points.sum() == prepared.log.points.sum() > 0
    assert (live.log.latency_s >= live.log.insert_s).all()
    summary = json.loads(json.dumps(live.summary()))
    assert summary["mapper"] == mapper and summary["frames"] == 3
    assert summary["feed"] == (live.info.feed.value)


def _cube(lo, hi) -> list[float]:
    """By hand: the cube anchored at ``lo`` whose edge is the box's longest side."""
    return [*map(float, lo), float(np.max(np.subtract(hi, lo)))]


def _as_list(domain: Domain) -> list[float]:
    return [domain.xmin, domain.ymin, domain.zmin, domain.size]


def test_domain_policies(terrain: Path, bag: Path) -> None:
    # sim_lan_1's control volume (scenario.json crop_box): x, y in [-35, 35], z in [-1, 12]
    crop = json.loads((terrain / "scenario.json").read_text())["crop_box"]
    assert crop == [-35.0, -35.0, -1.0, 35.0, 35.0, 12.0]
    on_terrain = run(terrain, MapSettings("alte2d"), FrameSettings(frames=2))
    assert on_terrain.info.domain_policy is DomainChoice.CONTROL
    assert _as_list(on_terrain.info.domain) == pytest.approx([-35.0, -35.0, -1.0, 70.0],
                                                             rel=1e-8)
    on_bag = run(bag, MapSettings("alte2d"), FrameSettings(frames=2))
    assert on_bag.info.domain_policy == "data"
    reg = prepare(open_input(bag), FrameSettings(frames=2))
    expected = _cube(reg.points.min(axis=0), reg.points.max(axis=0))
    assert _as_list(on_bag.info.domain) == pytest.approx(expected, rel=1e-8)
    assert on_bag.mapper.points_outside == 0
    explicit = Domain(-50.0, -50.0, -5.0, 100.0)
    chosen = run(terrain, MapSettings("alte3d", domain=explicit), FrameSettings(frames=2))
    assert (chosen.info.domain, chosen.info.domain_policy) == (explicit, "explicit")
    octo = run(terrain, MapSettings("octomap", PARAMS["octomap"]), FrameSettings(frames=2))
    assert octo.info.domain_policy is DomainChoice.NONE
    assert octo.summary()["domain_policy"] == "none (fixed key space)"
    with pytest.raises(ParameterError, match="domain policy 'control': the input has no "
                                             "control volume"):
        run(bag, MapSettings("alte2d", domain=DomainPolicy.CONTROL), FrameSettings(frames=2))


def test_quadtree_fed_by_frames_equals_its_batch_build(terrain: Path) -> None:
    reg = prepare(open_input(terrain), FrameSettings(frames=3))
    batch = run(reg, MapSettings("quadtree", PARAMS["quadtree"], feed=Feed.BATCH))
    frames = run(reg, MapSettings("quadtree", PARAMS["quadtree"], feed=Feed.FRAMES))
    _same_map(batch, frames)
    assert batch.log.insert_s[:-1].sum() == 0 and batch.log.insert_s[-1] > 0
    assert (frames.log.insert_s > 0).all()
    # CPU seconds beside the wall seconds, for the build only when batch-fed
    assert batch.log.insert_cpu_s[:-1].sum() == 0 and batch.cpu_s == batch.log.insert_cpu_s[-1]
    assert (frames.log.insert_cpu_s >= 0).all() and frames.cpu_s > 0
    summary = frames.summary()
    assert summary["cost"] == frames.mapper.cost > 0 and summary["cost_unit"] == "cell updates"


def test_snapshots_end_with_the_final_map(terrain: Path) -> None:
    result = run(terrain, MapSettings("alte2d", snapshots=2), FrameSettings(frames=4))
    assert [s.frame for s in result.snapshots] == [2, 3]
    assert result.snapshots[-1].basis_functions == result.mapper.basis_functions
    assert (np.diff(result.log.basis_functions) >= 0).all()
    assert result.snapshots[0].time < result.snapshots[1].time


def test_far_coordinates_get_a_local_origin(tmp_path: Path) -> None:
    rng = np.random.default_rng(3)
    points = rng.uniform(0, 20, (500, 3)) + np.array([512_345.0, 5_403_210.0, 300.0])
    path = write_points(tmp_path / "utm.npz", points)
    above = FrameSettings(origin=(512_355.0, 5_403_220.0, 400.0))
    result = run(path, MapSettings("octomap", {"resolution": 1.0}), above)
    origin = np.array(result.info.local_origin)
    assert (origin % 1000 == 0).all() and origin[0] == 512_000.0
    centers = result.mapper.cells().centers
    assert len(centers) and np.abs(centers).max() < 2000  # near its local origin
    assert result.mapper.points_outside == 0
    plain = run(path, MapSettings("alte3d", {"max_res": 4}), above)
    assert plain.info.local_origin == (0.0, 0.0, 0.0)  # a domain of its own: no shift


def test_a_prepared_input_fixes_its_frames(terrain: Path) -> None:
    reg = prepare(open_input(terrain), FrameSettings(frames=2))
    with pytest.raises(ParameterError, match="a prepared registration already fixes"):
        run(reg, MapSettings("alte2d"), FrameSettings(frames=1))
