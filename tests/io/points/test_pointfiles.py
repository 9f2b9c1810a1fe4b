"""Tests for alte.io.points.pointfiles: round trips, foreign writers (open3d, laspy), hand-made
PCD encodings, every error path and the real ISPRS / OctoMap samples."""

from __future__ import annotations

import bz2
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial import cKDTree

from alte.errors import ParameterError, PointFileError
from alte.io.points.pointfiles import (
    WRITE_SUFFIXES,
    local_origin,
    read_points,
    read_points_info,
    storable,
    write_points,
)
from alte.paths import realdata_dir

REALDATA = realdata_dir()
UTM = np.array([513_456.789, 5_403_210.123, 287.5])


@pytest.fixture
def cloud() -> np.ndarray:
    rng = np.random.default_rng(7)
    return UTM + rng.uniform(-150.0, 150.0, (500, 3))


def pcd_header(n, data, *, fields="x y z", sizes="4 4 4", types="F F F", counts="1 1 1"):
    return (
        f"# .PCD v0.7\nVERSION 0.7\nFIELDS {fields}\nSIZE {sizes}\nTYPE {types}\n"
        f"COUNT {counts}\nWIDTH {n}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {n}\nDATA {data}\n"
    ).encode()


def lzf_literals(data: bytes) -> bytes:
    """A valid LZF stream made of literal runs only (at most 32 bytes each)."""
    out = bytearray()
    for i in range(0, len(data), 32):
        chunk = data[i : i + 32]
        out += bytes([len(chunk) - 1]) + chunk
    return bytes(out)


# ------------------------------------------------------------------ round trips


@pytest.mark.parametrize("suffix", [s for s in WRITE_SUFFIXES if s not in (".las", ".laz")])
def test_round_trip_is_exact(tmp_path, cloud, suffix):
    path = write_points(tmp_path / f"cloud{suffix}", cloud)
    assert path == tmp_path / f"cloud{suffix}"
    back = read_points(path)
    assert back.dtype == np.float64
    np.testing.assert_array_equal(back, cloud)


@pytest.mark.parametrize("suffix", [".las", ".laz"])
def test_las_round_trip_within_quantisation(tmp_path, cloud, suffix):
    back = read_points(write_points(tmp_path / f"cloud{suffix}", cloud))
    assert np.abs(back - cloud).max() <= 0.5e-4 + 1e-9


def test_laz_is_compressed(tmp_path, cloud):
    las = write_points(tmp_path / "c.las", cloud).stat().st_size
    laz = write_points(tmp_path / "c.laz", cloud).stat().st_size
    assert laz < las


def test_suffix_is_case_insensitive(tmp_path, cloud):
    np.testing.assert_array_equal(read_points(write_points(tmp_path / "C.PCD", cloud)), cloud)


# ------------------------------------------------------------------ foreign writers


@pytest.mark.parametrize(
    ("suffix", "kwargs"),
    [
        (".pcd", {"write_ascii": True}),
        (".pcd", {"write_ascii": False}),
        (".pcd", {"write_ascii": False, "compressed": True}),
        (".ply", {"write_ascii": False}),
        (".ply", {"write_ascii": True}),
    ],
)
def test_reads_what_open3d_writes(tmp_path, suffix, kwargs):
    import open3d as o3d

    pts = np.random.default_rng(3).uniform(-20, 20, (300, 3)).astype(np.float32)
    pts[:50] = pts[0]  # repeats give LZF back-references to decode
    cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(pts.astype(np.float64)))
    path = tmp_path / f"o3d{suffix}"
    assert o3d.io.write_point_cloud(str(path), cloud, **kwargs)
    np.testing.assert_allclose(read_points(path), pts, rtol=0, atol=1e-4)  # ascii: 6 digits


def test_reads_what_laspy_writes(tmp_path):
    import laspy

    header = laspy.LasHeader(point_format=3, version="1.4")
    header.offsets, header.scales = [500000.0, 5400000.0, 0.0], [0.01, 0.01, 0.01]
    las = laspy.LasData(header)
    las.x = np.array([500001.25, 500002.5])
    las.y = np.array([5400003.75, 5400004.0])
    las.z = np.array([10.0, 11.01])
    las.write(tmp_path / "l.las")
    expected = [[500001.25, 5400003.75, 10.0], [500002.5, 5400004.0, 11.01]]
    np.testing.assert_allclose(read_points(tmp_path / "l.las"), expected, atol=1e-9)


# ------------------------------------------------------------------ PCD encodings


def test_pcd_ascii_with_multi_count_field_and_nan(tmp_path):
    head = pcd_header(
        3,
        "ascii",
        fields="normal x y z rgb",
        sizes="4 4 4 4 4",
        types="F F F F U",
        counts="3 1 1 1 1",
    )
    rows = b"0 0 1 1.5 2.5 3.5 255\n0 0 1 nan nan nan 0\n0 0 1 -4 5e1 6 7\n"
    (tmp_path / "a.pcd").write_bytes(head + rows)
    info = read_points_info(tmp_path / "a.pcd")
    np.testing.assert_array_equal(info.points, [[1.5, 2.5, 3.5], [-4.0, 50.0, 6.0]])
    assert (info.rows, info.nonfinite) == (3, 1)


def test_pcd_binary_with_mixed_field_types(tmp_path):
    dtype = np.dtype([("i", "u1"), ("x", "<f8"), ("y", "<f4"), ("z", "<i2"), ("t", "<u4")])
    data = np.array([(7, 1.25, 2.5, -3, 9), (8, 512345.678, -1.0, 40, 10)], dtype)
    head = pcd_header(
        2,
        "binary",
        fields="intensity x y z t",
        sizes="1 8 4 2 4",
        types="U F F I U",
        counts="1 1 1 1 1",
    )
    (tmp_path / "b.pcd").write_bytes(head + data.tobytes())
    np.testing.assert_array_equal(
        read_points(tmp_path / "b.pcd"), [[1.25, 2.5, -3.0], [512345.678, -1.0, 40.0]]
    )


def test_pcd_binary_compressed_literals_and_back_reference(tmp_path):
    x = np.array([1.0, 2.0, 3.0], "<f4").tobytes()
    y = np.array([4.0, 5.0, 6.0], "<f4").tobytes()
    z = np.zeros(3, "<f4").tobytes()  # 12 zero bytes: one literal + an 11-byte back-reference
    body = x + y + z
    stream = lzf_literals(x + y) + bytes([0, 0]) + bytes([(7 << 5) | 0, 2, 0])
    blob = np.array([len(stream), len(body)], "<u4").tobytes() + stream
    head = pcd_header(3, "binary_compressed")
    (tmp_path / "c.pcd").write_bytes(head + blob)
    np.testing.assert_array_equal(
        read_points(tmp_path / "c.pcd"), [[1, 4, 0], [2, 5, 0], [3, 6, 0]]
    )


# ------------------------------------------------------------------ text


def test_text_any_whitespace_extra_columns_comments_and_bz2(tmp_path):
    text = b"# x y z intensity\n1 2 3 9\n4\t5   6 9\n  7 8 9 9\n"
    (tmp_path / "p.txt").write_bytes(text)
    (tmp_path / "p.xyz.bz2").write_bytes(bz2.compress(text))
    expected = [[1, 2, 3], [4, 5, 6], [7, 8, 9]]
    np.testing.assert_array_equal(read_points(tmp_path / "p.txt"), expected)
    np.testing.assert_array_equal(read_points(tmp_path / "p.xyz.bz2"), expected)


def test_npz_points_array(tmp_path):
    np.savez(tmp_path / "p.npz", points=np.arange(6, dtype=np.float32).reshape(2, 3))
    np.testing.assert_array_equal(read_points(tmp_path / "p.npz"), [[0, 1, 2], [3, 4, 5]])


# ------------------------------------------------------------------ read errors


def test_missing_file(tmp_path):
    with pytest.raises(PointFileError, match=r"nope\.pcd: no such point file"):
        read_points(tmp_path / "nope.pcd")


def test_unknown_extension_lists_supported(tmp_path):
    (tmp_path / "p.e57").write_bytes(b"x")
    with pytest.raises(PointFileError, match=r"p\.e57: unknown point file type; supported:.*\.laz"):
        read_points(tmp_path / "p.e57")


@pytest.mark.parametrize(
    ("name", "content", "match"),
    [
        ("a.pcd", b"hello\nworld\n", "no DATA line"),
        (
            "b.pcd",
            pcd_header(1, "binary", fields="x y q"),
            "lack x, y and z",
        ),
        (
            "c.pcd",
            pcd_header(1, "binary", sizes="4 4"),
            "lengths differ",
        ),
        (
            "d.pcd",
            pcd_header(1, "binary", types="Q Q Q"),
            "bad PCD field types",
        ),
        (
            "e.pcd",
            pcd_header(1, "zip"),
            "unknown PCD DATA",
        ),
        (
            "f.pcd",
            pcd_header(5, "binary") + b"\0" * 12,
            r"truncated binary PCD: 12 of the 60 bytes \(1 of 5 rows\) its header announces",
        ),
        (
            "g.pcd",
            pcd_header(1, "binary_compressed") + b"\1",
            "truncated binary_compressed PCD: 1 bytes after the header",
        ),
        (
            "h.pcd",
            pcd_header(1, "binary_compressed") + np.array([3, 99], "<u4").tobytes() + b"abc",
            "sizes do not match the header: the body unpacks to 99 bytes, 1 rows need 12",
        ),
        (
            "h2.pcd",
            pcd_header(9, "binary_compressed") + np.array([40, 108], "<u4").tobytes() + b"abc",
            r"truncated binary_compressed PCD: 3 of the 40 compressed bytes \(9 rows\)",
        ),
        (
            "h3.pcd",
            pcd_header(4, "ascii") + b"1 2 3\n4 5 6\n",
            "truncated ascii PCD: 2 of the 4 rows its header announces",
        ),
        (
            "h4.pcd",
            pcd_header(2, "ascii") + b"1 2 3\n4 5\n",
            "truncated ascii PCD: its last row has 2 of 3 values",
        ),
        (
            "h5.pcd",
            pcd_header(3, "ascii"),
            "truncated ascii PCD: 0 of the 3 rows",
        ),
        (
            "h6.pcd",
            pcd_header(4, "binary").replace(b"HEIGHT 1", b"HEIGHT 2") + b"\0" * 96,
            r"PCD header says WIDTH 4 x HEIGHT 2 = 8 points but POINTS 4",
        ),
        (
            "i.pcd",
            pcd_header(1, "binary_compressed")
            + np.array([3, 12], "<u4").tobytes()
            + b"\xe0\x00\x05",
            "corrupt LZF",
        ),
        (
            "j.pcd",
            pcd_header(0, "binary"),
            "no points",
        ),
        (
            "k.pcd",
            pcd_header(1, "ascii") + b"1 2\n",
            "2 ascii columns",
        ),
        ("p.ply", b"ply\ngarbage\n", "not a PLY file"),
        ("l.las", b"LASF" + b"\0" * 50, "unreadable"),
        ("t.xyz", b"1 2\n3 4\n", "2 column"),
        ("u.xyz", b"1 2 3\na b c\n", "unreadable"),
        ("v.xyz", b"1 2 3\n4 5 6 7\n", "unreadable"),
        ("w.xyz", b"", "unreadable"),
        ("x.xyz", b"nan 1 2\n1 inf 2\n", r"no finite points \(2 rows\)"),
        ("y.xyz.bz2", b"not bzip2", "unreadable"),
    ],
)
def test_corrupt_files(tmp_path, name, content, match):
    (tmp_path / name).write_bytes(content)
    with pytest.raises(PointFileError, match=match) as info:
        read_points(tmp_path / name)
    assert name in str(info.value)


def test_npz_errors(tmp_path):
    np.savez(tmp_path / "a.npz", xyz=np.zeros((2, 3)))
    np.savez(tmp_path / "b.npz", points=np.zeros((2, 4)))
    with pytest.raises(PointFileError, match=r"a\.npz: no 'points' array"):
        read_points(tmp_path / "a.npz")
    with pytest.raises(PointFileError, match=r"b\.npz: points have shape \(2, 4\)"):
        read_points(tmp_path / "b.npz")


# ------------------------------------------------------------------ write errors


def test_refuses_to_overwrite_silently(tmp_path, cloud):
    path = write_points(tmp_path / "c.ply", cloud)
    with pytest.raises(PointFileError, match=r"c\.ply already exists"):
        write_points(path, cloud[:10])
    write_points(path, cloud[:10], overwrite=True)
    assert len(read_points(path)) == 10
    assert sorted(p.name for p in tmp_path.iterdir()) == ["c.ply"]  # no temp files left


@pytest.mark.parametrize(
    ("name", "points", "match"),
    [
        ("a.e57", np.zeros((2, 3)), "cannot write this type; supported"),
        ("b.pcd", np.zeros((2, 2)), r"shape \(N, 3\)"),
        ("c.pcd", np.zeros((0, 3)), r"N > 0"),
        ("d.las", np.array([[0.0, np.nan, 1.0]]), "non-finite"),
        ("e.las", np.array([[0.0, 0.0, 0.0], [1e6, 0.0, 0.0]]), "too far for LAS"),
    ],
)
def test_write_errors(tmp_path, name, points, match):
    with pytest.raises(PointFileError, match=match):
        write_points(tmp_path / name, points)
    assert list(tmp_path.iterdir()) == []


# ------------------------------------------------------------------ local origin


def test_local_origin_rounds_the_centre(cloud):
    origin = local_origin(cloud)
    np.testing.assert_array_equal(origin, [513_000.0, 5_403_000.0, 0.0])
    local = cloud - origin
    assert np.abs(local).max() < 1000.0
    np.testing.assert_array_equal(local + origin, cloud)  # the shift loses nothing
    np.testing.assert_array_equal(
        local_origin(cloud, quantum=10.0), [513_460.0, 5_403_210.0, 290.0]
    )


def test_local_origin_is_zero_near_the_origin():
    pts = np.array([[-5.0, -3.0, -1.0], [4.0, 2.0, 0.5]])
    origin = local_origin(pts)
    np.testing.assert_array_equal(origin, np.zeros(3))
    assert not np.signbit(origin).any()


@pytest.mark.parametrize(
    ("points", "quantum", "match"),
    [
        (np.zeros((1, 3)), 0.0, "quantum"),
        (np.zeros((1, 3)), float("nan"), "quantum"),
        (np.zeros((0, 3)), 1.0, r"N > 0"),
        (np.zeros((2, 2)), 1.0, r"\(N, 3\)"),
        (np.array([[np.inf, 0, 0]]), 1.0, "non-finite"),
    ],
)
def test_local_origin_errors(points, quantum, match):
    with pytest.raises(ParameterError, match=match):
        local_origin(points, quantum)


# ------------------------------------------------------------------ real samples


def _realdata(*parts: str) -> Path:
    path = REALDATA.joinpath(*parts)
    if not path.exists():
        pytest.skip(f"../shared/realdata/{'/'.join(parts)} absent")
    return path


def _header_points(path: Path) -> int:
    for line in path.read_bytes().split(b"\n")[:12]:
        if line.startswith(b"POINTS"):
            return int(line.split()[1])
    raise AssertionError(path)


@pytest.mark.realdata
@pytest.mark.parametrize("sample", ["samp11", "samp21", "samp31"])
def test_isprs_ground_is_a_subset_of_the_sample(sample):
    full_path = _realdata("isprs_terrain", f"{sample}-utm.pcd")
    ground_path = _realdata("isprs_terrain", f"{sample}-utm-ground.pcd")
    full, ground = read_points(full_path), read_points(ground_path)
    assert len(full) == _header_points(full_path)
    assert len(ground) == _header_points(ground_path)
    assert len(ground) < len(full)
    origin = local_origin(full)
    assert origin[0] % 1000 == 0 and 5e6 < origin[1] < 6e6  # UTM 32U northing
    local = full - origin
    assert np.abs(local).max() < 1000.0
    ulp = np.spacing(np.abs(full).max(axis=0).astype(np.float32)).max()  # float32 quantum
    dist, _ = cKDTree(local).query(ground - origin)
    assert dist.max() <= ulp


@pytest.mark.realdata
def test_octomap_scan_count_matches_sources():
    points = read_points(_realdata("octomap_scan", "scan.dat.bz2"))
    assert points.shape == (88_206, 3)
    np.testing.assert_array_equal(local_origin(points), np.zeros(3))  # sensor at the origin


@pytest.mark.realdata
def test_nebula_reference_pcd_count_matches_sources():
    points = read_points(_realdata("vlp16_packets", "reference_decoded.pcd"))
    assert points.shape == (14_831, 3)


# ------------------------------------------------------------------ other fields


def _fields(n: int) -> dict[str, np.ndarray]:
    rng = np.random.default_rng(3)
    return {"intensity": rng.integers(0, 65535, n).astype(np.uint16),
            "colors": rng.integers(0, 256, (n, 3)).astype(np.uint8),
            "label": rng.integers(-5, 1000, n).astype(np.int32),
            "range": rng.uniform(0, 100, n).astype(np.float32)}


@pytest.mark.parametrize("suffix", [".pcd", ".ply", ".npz", ".las", ".laz"])
def test_fields_survive_the_formats_that_hold_them(tmp_path, cloud, suffix):
    fields = _fields(len(cloud))
    back = read_points_info(write_points(tmp_path / f"f{suffix}", cloud, fields=fields))
    assert set(back.fields) == set(fields)
    for name, values in fields.items():
        np.testing.assert_array_equal(back.fields[name], values, err_msg=name)


def test_fields_a_format_cannot_hold_are_named(tmp_path, cloud):
    fields = {**_fields(len(cloud)), "intensity": np.linspace(0, 1, len(cloud))}
    kept, dropped = storable(".las", fields)
    assert dropped == {"intensity": "LAS intensity holds integers 0..65535"}
    assert set(kept) == {"colors", "label", "range"}
    assert storable(".xyz", fields)[1]["label"] == "plain text holds x y z only"
    back = read_points_info(write_points(tmp_path / "f.xyz", cloud, fields=fields))
    assert back.fields == {}
    with pytest.raises(PointFileError, match=r"fields \['label'\] do not have one row per point"):
        write_points(tmp_path / "g.pcd", cloud, fields={"label": np.zeros(3)})


def test_pcd_fields_rgb_and_nan_rows(tmp_path):
    rgb = np.array([0xFF0000, 0x00FF00, 0x0000FF], "<u4").view("<f4")
    data = np.zeros(3, [("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("rgb", "<f4"),
                        ("label", "<u4")])
    data["x"], data["rgb"], data["label"] = [1, np.nan, 3], rgb, [7, 8, 9]
    head = pcd_header(3, "binary", fields="x y z rgb label", sizes="4 4 4 4 4",
                      types="F F F F U", counts="1 1 1 1 1")
    (tmp_path / "c.pcd").write_bytes(head + data.tobytes())
    info = read_points_info(tmp_path / "c.pcd")
    assert info.nonfinite == 1 and info.fields["label"].tolist() == [7, 9]
    assert info.fields["colors"].tolist() == [[255, 0, 0], [0, 0, 255]]
    out = write_points(tmp_path / "d.pcd", info.points, fields=info.fields)
    assert b"FIELDS x y z rgb label" in out.read_bytes()[:200]
    assert read_points_info(out).fields["colors"].tolist() == [[255, 0, 0], [0, 0, 255]]
