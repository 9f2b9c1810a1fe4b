"""Native vs reference OctoMap on the simulated benchmark mission: sim_nav_1, 5 cells/m.

Frame by frame, same origins, thesis (MATLAB) sensor model, 100 m max range: the
occupied voxel sets must be identical (Jaccard 1.0) and so must the leaf counts.
Three scans spread over the mission keep the test to seconds (a ray dropped, an origin
moved by 1 mm or the map reset between scans each fail it, as with twelve scans; clamping
is reached by neither); ``alte bench`` runs the full one. The
scan kernels' paths (the lane walk in a flat grid or the hashed block set) must give the
very same key sets.
"""

from __future__ import annotations

import numpy as np
import pytest

from alte.mappers.octomap import compare_backends
from alte.mappers.octomap import scan as _scan
from alte.mappers.octree.blockset import WORDS
from alte.pipeline import open_input, prepare
from alte.sim import ensure_terrain


@pytest.fixture(scope="module")
def three_scans(tmp_path_factory):
    """SIM NAV 1 simulated with three scans: shared by the agreement and flat-grid tests."""
    return ensure_terrain("sim_nav_1", tmp_path_factory.mktemp("data"), frames=3)


@pytest.mark.slow
def test_native_agrees_with_reference_on_sim_nav_1(three_scans):
    scans = [(np.array(f.points), f.origin) for f in prepare(open_input(three_scans)).frames()]
    result = compare_backends(scans, resolution=5.0, max_range=100.0)
    assert result["jaccard"] == 1.0, result
    assert result["leaf_count_native"] == result["leaf_count_reference"] > 0, result


def _sorted(blocks: np.ndarray, bits: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    order = np.argsort(blocks)
    return blocks[order], bits[order]


@pytest.mark.slow
def test_lane_walk_and_hashed_scans_give_the_same_keys(tmp_path_factory, monkeypatch):
    folder = ensure_terrain("sim_nav_1", tmp_path_factory.mktemp("data"), frames=6)
    work = _scan.ScanWork()  # reused by every scan, as a map does: left clean by each
    for frame in prepare(open_input(folder)).frames():
        points, origin = np.array(frame.points), frame.origin
        args = (points.astype(np.float32), origin.astype(np.float32), 0.2, 100.0)
        dense = _sorted(*_scan.scan_blocks(*args, work))
        assert dense[0].size > 100 and (dense[1][:, :WORDS] & dense[1][:, WORDS:] == 0).all()
        assert not work.grid.any() and (work.cell == -1).all()
        with monkeypatch.context() as patch:
            patch.setattr(_scan, "DENSE_MAX_WORDS", 0)  # every scan takes the hashed path
            hashed = _sorted(*_scan.scan_blocks(*args, _scan.ScanWork()))
        assert all(np.array_equal(a, b) for a, b in zip(dense, hashed, strict=True))


@pytest.mark.slow
def test_large_flat_grids_follow_the_words_per_step_rule(three_scans, monkeypatch):
    monkeypatch.setattr(_scan, "DENSE_ANY_WORDS", 0)  # every grid counts as large
    for frame in prepare(open_input(three_scans)).frames():
        args = (np.array(frame.points, np.float32), frame.origin.astype(np.float32), 0.1, 100.0)
        runs = {}
        for per_step in (0, 10**6):  # no grid is cheap enough / every grid is
            monkeypatch.setattr(_scan, "WORDS_PER_STEP", per_step)
            work = _scan.ScanWork()
            runs[per_step] = _sorted(*_scan.scan_blocks(*args, work))
            assert (work.grid.size > 1) == (per_step > 0)  # the flat grid was used or not
        assert runs[0][0].size > 100
        assert all(np.array_equal(a, b) for a, b in zip(runs[0], runs[10**6], strict=True))
