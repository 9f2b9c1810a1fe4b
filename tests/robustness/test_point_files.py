"""Bad point files through ``alte map`` (the batch entry point for clouds)."""

from __future__ import annotations

import numpy as np
import pytest

from alte.io.pointfiles import write_points

CLOUD = np.random.default_rng(0).uniform(0.0, 10.0, (2000, 3))


@pytest.mark.parametrize("suffix", [".ply", ".pcd", ".las", ".laz", ".npz"])
@pytest.mark.parametrize("fraction", [0.1, 0.6])
def test_truncated_point_file(bags, capsys, tmp_path, suffix, fraction):
    path = write_points(tmp_path / f"cloud{suffix}", CLOUD)
    blob = path.read_bytes()
    path.write_bytes(blob[: int(len(blob) * fraction)])
    code, out, err = bags.run_cli(capsys, "map", path, "--mapper", "alte2d", "--json")
    assert code == 2, out
    assert str(path) in bags.one_line_error(err, "map")


def test_truncated_ascii_ply(bags, capsys, tmp_path):
    path = tmp_path / "cloud.ply"
    rows = "\n".join(f"{x} {y} {z}" for x, y, z in CLOUD[:5])
    path.write_text("ply\nformat ascii 1.0\nelement vertex 10\nproperty float x\n"
                    f"property float y\nproperty float z\nend_header\n{rows}\n")
    code, out, err = bags.run_cli(capsys, "map", path, "--mapper", "alte2d", "--json")
    assert code == 2, out
    assert "truncated PLY (5 of 10 rows" in bags.one_line_error(err, "map")


def test_missing_point_file(bags, capsys, tmp_path):
    code, _, err = bags.run_cli(capsys, "map", tmp_path / "cloud.ply", "--mapper", "alte2d")
    line = bags.one_line_error(err, "map")
    assert code == 2 and f"{tmp_path / 'cloud.ply'}: no such point file" in line


def test_text_file_with_two_columns(bags, capsys, tmp_path):
    path = tmp_path / "cloud.xyz"
    path.write_text("1 2\n3 4\n")
    code, _, err = bags.run_cli(capsys, "map", path, "--mapper", "alte2d")
    assert code == 2
    assert f"{path}: 2 column(s); expected x y z per line" in bags.one_line_error(err, "map")


@pytest.mark.parametrize("mapper", ["quadtree", "alte2d", "alte3d", "octomap"])
def test_nonfinite_points_in_a_file_are_dropped_and_counted(bags, capsys, tmp_path, mapper):
    """NaN/inf rows (e.g. ``is_dense = false`` exports) are dropped, and the user is told."""
    path = tmp_path / "cloud.xyz"
    path.write_text("1 2 3\nnan 0 0\n4 5 6\n2 inf 2\n2 2 2\n")
    code, out, err = bags.run_cli(capsys, "map", path, "--mapper", mapper)
    assert code == 0, err
    assert "points: 3\n" in out and "points_dropped_nonfinite: 2\n" in out


def test_only_nonfinite_points(bags, capsys, tmp_path):
    path = tmp_path / "cloud.xyz"
    path.write_text("nan 0 0\n0 inf 0\n")
    code, _, err = bags.run_cli(capsys, "map", path, "--mapper", "alte2d")
    assert code == 2
    assert f"{path}: no finite points (2 rows)" in bags.one_line_error(err, "map")
