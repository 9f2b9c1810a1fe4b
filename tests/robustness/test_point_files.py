"""Bad point files through ``alte map`` (the batch entry point for clouds)."""

from __future__ import annotations

import re

import numpy as np
import pytest

from alte.io.points.pointfiles import write_points

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


def _ascii_pcd(path, rows, points, width=None):
    body = "".join(f"{x} {y} {z}\n" for x, y, z in CLOUD[:rows])
    path.write_text("VERSION 0.7\nFIELDS x y z\nSIZE 8 8 8\nTYPE F F F\nCOUNT 1 1 1\n"
                    f"WIDTH {width or points}\nHEIGHT 1\nPOINTS {points}\nDATA ascii\n{body}")
    return path


@pytest.mark.parametrize("command", ["map", "register"])
def test_truncated_ascii_pcd_is_refused_with_the_row_counts(bags, capsys, tmp_path, command):
    """Half the rows of an ascii PCD: PCL refuses it, so does alte (it used to read 1000)."""
    path = _ascii_pcd(tmp_path / "half.pcd", 1000, 2000)
    extra = ["--mapper", "alte2d"] if command == "map" else ["--out", tmp_path / "c.ply"]
    code, out, err = bags.run_cli(capsys, command, path, *extra)
    assert code == 2, out
    assert f"{path}: truncated ascii PCD: 1000 of the 2000 rows its header announces" in \
        bags.one_line_error(err, command)
    assert not (tmp_path / "c.ply").exists()


@pytest.mark.parametrize(("encoding", "message"), [
    ("binary", r"truncated binary PCD: 24000 of the 48000 bytes \(1000 of 2000 rows\)"),
    ("binary_compressed", "binary_compressed sizes do not match the header: the body unpacks "
                          "to 24000 bytes, 2000 rows need 48000"),
])
def test_a_header_claiming_more_points_than_rows_is_refused(bags, capsys, tmp_path, encoding,
                                                            message):
    path = write_points(tmp_path / "c.pcd", CLOUD[:1000])
    blob = path.read_bytes().replace(b"WIDTH 1000", b"WIDTH 2000").replace(b"POINTS 1000",
                                                                           b"POINTS 2000")
    if encoding == "binary_compressed":  # literal-only LZF of the same 1000 rows, field-major
        head, body = blob.split(b"DATA binary\n")
        raw = np.frombuffer(body, "<f8").reshape(-1, 3).T.copy().tobytes()
        lzf = b"".join(bytes([len(raw[i:i + 32]) - 1]) + raw[i:i + 32]
                       for i in range(0, len(raw), 32))
        blob = head + b"DATA binary_compressed\n" + np.array(
            [len(lzf), len(raw)], "<u4").tobytes() + lzf
    path.write_bytes(blob)
    code, out, err = bags.run_cli(capsys, "map", path, "--mapper", "alte2d")
    assert code == 2, out
    line = bags.one_line_error(err, "map")
    assert str(path) in line and re.search(message, line), line


def test_width_times_height_must_match_points(bags, capsys, tmp_path):
    path = _ascii_pcd(tmp_path / "w.pcd", 10, 10, width=12)
    code, _, err = bags.run_cli(capsys, "map", path, "--mapper", "alte2d")
    assert code == 2
    assert "PCD header says WIDTH 12 x HEIGHT 1 = 12 points but POINTS 10" in \
        bags.one_line_error(err, "map")
