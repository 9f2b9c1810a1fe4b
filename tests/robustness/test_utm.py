"""UTM-scale coordinates (1e6-1e7 m) through ``alte map``, on the real ISPRS samples.

Every mapper must give the same cells for the georeferenced cloud as for the same
cloud moved next to 0 by hand: domain-anchored mappers are exact at any offset;
Octomap (fixed key space around 0, float32 ray casting) is mapped relative to a
round local origin that the summary reports and the export adds back.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from alte.io.points.pointfiles import local_origin, read_points, write_points

SETS = {
    "quadtree": ["--set", "max_points=50", "--set", "ground=300"],
    "alte2d": ["--set", "kappa=0.5", "--set", "max_res=8"],
    "alte3d": ["--set", "max_res=6", "--set", "min_pts=2", "--set", "occupancy_level=0"],
    "octomap": ["--set", "resolution=2", "--set", "max_range=-1"],
}


def _map(bags, capsys, cloud: Path, mapper: str, *, origin: np.ndarray, out: Path) -> dict:
    code, text, err = bags.run_cli(
        capsys, "map", cloud, "--mapper", mapper, *SETS[mapper], "--voxel", "4", "--json",
        f"--origin={','.join(repr(float(v)) for v in origin)}", "--export", out)
    assert code == 0, err
    return json.loads(text)


@pytest.mark.realdata
@pytest.mark.parametrize("mapper", sorted(SETS))
@pytest.mark.parametrize("sample", ["samp11", "samp31"])
def test_utm_cloud_maps_like_the_same_cloud_near_zero(bags, capsys, tmp_path, mapper, sample):
    utm = bags.realdata("isprs_terrain", f"{sample}-utm.pcd")
    points = read_points(utm)
    assert np.abs(points).max() > 1e6  # really UTM scale
    shift = local_origin(points)
    local = write_points(tmp_path / "local.npz", points - shift)
    sensor = np.r_[points[:, :2].mean(axis=0), points[:, 2].max() + 50.0]
    far = _map(bags, capsys, utm, mapper, origin=sensor, out=tmp_path / "utm.npz")
    near = _map(bags, capsys, local, mapper, origin=sensor - shift, out=tmp_path / "near.npz")
    assert far["points"] == near["points"] and far["points_outside"] == 0
    assert far["basis_functions"] == near["basis_functions"]
    assert far["occupied_cells"] == near["occupied_cells"] > 0
    with np.load(tmp_path / "utm.npz") as a, np.load(tmp_path / "near.npz") as b:
        for name in ("level", "occupied"):
            np.testing.assert_array_equal(a[name], b[name])
        np.testing.assert_allclose(a["sizes"], b["sizes"], rtol=0, atol=1e-6)
        assert shift[2] == 0.0  # terrain heights stay as they are: values compare directly
        np.testing.assert_allclose(a["value"], b["value"], rtol=0, atol=1e-9, equal_nan=True)
        # cell centres agree to far better than a centimetre in georeferenced coordinates
        np.testing.assert_allclose(a["centers"] - shift, b["centers"], rtol=0, atol=1e-6)
    if mapper == "octomap":  # mapped near a round local origin, on the same voxel grid
        used = np.array(far["local_origin"])
        assert np.abs(used).max() > 1e5 and (np.mod(used, 1000.0) == 0).all()
        assert np.abs(points - used).max() < 2000.0
    else:
        assert far["local_origin"] == [0.0, 0.0, 0.0]


@pytest.mark.parametrize("mapper", ["octomap", "alte2d"])
def test_utm_bag_maps_like_the_same_bag_near_zero(bags, capsys, tmp_path, mapper):
    """Poses at UTM scale (x 513 km, y 5404 km): frame-by-frame mapping as near the origin."""
    from alte.io.bags.writer import write_frames
    from alte.types import Frame, Mount

    rng = np.random.default_rng(3)
    below = np.array([0.0, 0.0, -4.0])
    scans = [rng.uniform(-3.0, 3.0, (150, 3)) + below for _ in range(4)]
    summaries, cells = [], []
    for name, offset in (("near", np.zeros(3)), ("utm", np.array([513_000.0, 5_404_000.0, 0.0]))):
        frames = [Frame(10**10 + k * 10**8, pts, offset + np.array([0.5 * k, 0.0, 5.0]),
                        np.array([0.0, 0.0, 0.0, 1.0])) for k, pts in enumerate(scans)]
        bag = write_frames(tmp_path / name, frames, Mount(), dtype=np.float64)
        code, text, err = bags.run_cli(capsys, "map", bag, "--mapper", mapper, "--json",
                                       "--export", tmp_path / f"{name}.npz")
        assert code == 0, err
        summaries.append(json.loads(text))
        with np.load(tmp_path / f"{name}.npz") as data:
            cells.append({k: data[k] for k in data.files})
    near, utm = summaries
    assert near["occupied_cells"] == utm["occupied_cells"] > 0
    assert near["basis_functions"] == utm["basis_functions"]
    np.testing.assert_array_equal(cells[0]["occupied"], cells[1]["occupied"])
    np.testing.assert_allclose(cells[1]["centers"] - (513_000.0, 5_404_000.0, 0.0),
                               cells[0]["centers"], rtol=0, atol=1e-6)
