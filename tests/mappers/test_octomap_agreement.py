"""Native vs reference OctoMap on the simulated benchmark (mappers issue): sim_nav_1, 5 cells/m.

Frame by frame, same origins, thesis (MATLAB) sensor model, 100 m max range: the
occupied voxel sets must have Jaccard >= 0.999 and the leaf counts differ by < 1 %.
A reduced mission keeps the test to seconds; ``make bench`` runs the full one.
"""

from __future__ import annotations

import numpy as np
import pytest

from alte.mappers.octomap import compare_backends
from alte.pipeline import open_input, prepare
from alte.sim import ensure_terrain


@pytest.mark.slow
def test_native_agrees_with_reference_on_sim_nav_1(tmp_path_factory):
    folder = ensure_terrain("sim_nav_1", tmp_path_factory.mktemp("data"), frames=12)
    data = prepare(open_input(folder))
    scans = [(np.array(f.points), f.origin) for f in data.frames()]
    result = compare_backends(scans, resolution=5.0, max_range=100.0)
    assert result["jaccard"] >= 0.999, result
    leaves = result["leaf_count_native"], result["leaf_count_reference"]
    assert abs(leaves[0] - leaves[1]) < 0.01 * leaves[1], result
