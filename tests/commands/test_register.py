"""Tests for ``alte register``: a real bag end to end, and the command's own logic."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from support.synthetic import make_frame, scene

from alte.cli import main
from alte.commands import register as command
from alte.commands.options import parse_box
from alte.commands.register import format_counts
from alte.errors import ParameterError
from alte.io import read_frames, write_frames
from alte.io.bags.bag import ReadCounts, ReadSettings
from alte.io.points.pointfiles import read_points, read_points_info
from alte.paths import realdata_dir
from alte.pipeline import InputKind, Source
from alte.pipeline import source as source_module
from alte.registration import RegistrationCounts, crop, grid_average, register_frame
from alte.types import Mount

BOX = (-4.0, -4.0, -4.0, 4.0, 4.0, 4.0)


def test_register_bag_end_to_end(tmp_path, capsys):
    truth, frames, mount = scene(seed=5, frames=5, n=300)
    bag = write_frames(tmp_path / "scans", frames, mount, dtype=np.float64)
    out = tmp_path / "cloud.npz"
    box = ",".join(str(v) for v in BOX)
    argv = ["register", str(bag), "--out", str(out), "--voxel", "0.5", f"--crop={box}"]
    assert main(argv) == 0
    expected = grid_average(np.vstack([crop(t, BOX) for t in truth]), 0.5)
    got = read_points(out)
    def rows(a):
        return a[np.lexsort(a.T[::-1])]

    assert got.shape == expected.shape
    np.testing.assert_allclose(rows(got), rows(expected), atol=1e-9)
    text = capsys.readouterr().out
    assert "frames: 5 in, 5 kept" in text
    assert f"{len(expected)} out" in text
    assert main(argv) == 2  # exists, no --force
    assert "already exists" in capsys.readouterr().err
    assert main([*argv, "--force"]) == 0


@pytest.fixture
def fake_io(monkeypatch):
    """Replace the bag stream and point writer by in-memory fakes."""
    _truth, frames, mount = scene(seed=1, frames=3, n=100)
    frames.append(make_frame(frames[0].points, frames[0].position, frames[0].quaternion,
                             rate=9.0))
    calls: dict[str, object] = {}

    class Stream:
        def __init__(self, path, options, **kwargs):
            calls["read"] = (path, options, kwargs)
            self.mount = kwargs["mount"] or mount
            self.scans = self.selected = len(frames)
            self.notes: list[str] = []
            self.counts = ReadCounts(scans_read=len(frames))
            self.track = object()  # a recorded pose stream: the frames keep their poses
            self.options = options  # read as FrameStream reads (deskew's gap limit)

        def __iter__(self):
            return iter(frames)

    def write_points(path, points, overwrite=False, fields=None):
        calls["write"] = (path, points, overwrite, fields)
        Path(path).write_text("cloud")

    monkeypatch.setattr(command, "open_input",
                        lambda path: Source(Path(path), InputKind.BAG, bag=Path(path)))
    monkeypatch.setattr(source_module, "FrameStream", Stream)
    monkeypatch.setattr(command, "write_points", write_points)
    return calls


def test_command_passes_options_and_prints_counts(tmp_path, capsys, fake_io):
    out = tmp_path / "c.ply"
    argv = ["register", "bag", "--out", str(out), "--max-rate", "1", "--cloud-topic", "/c",
            "--pose-topic", "/p", "--mount", "0,0,0,0,0,90"]
    assert main(argv) == 0
    path, options, kwargs = fake_io["read"]
    assert str(path) == "bag"
    assert (options.cloud_topic, options.pose_topic, options.progress) == ("/c", "/p", True)
    np.testing.assert_allclose(kwargs["mount"].quaternion, Mount.from_string(
        "0,0,0,0,0,90").quaternion)
    written = fake_io["write"]
    assert written[1].shape == (300, 3)
    assert written[2] is False
    text = capsys.readouterr().out
    assert "bag: scans read 4" in text
    assert "frames: 4 in, 3 kept; dropped 1 (angular rate)" in text
    assert "points: 300 in" in text
    assert f"wrote 300 points to {out}" in text


@pytest.mark.parametrize(("extra", "match"), [
    (["--crop", "1,2,3"], "--crop '1,2,3': expected 6 numbers"),
    (["--crop", "a,b,c,d,e,f"], "expected 6 numbers"),
    (["--crop", "1,1,1,0,0,0"], "min must be <= max"),
    (["--voxel", "0"], "--voxel: frame spec: voxel=0.0 out of range (voxel > 0, finite)"),
    (["--max-offset", "-1"], "--max-offset: frame spec: max_offset=-1.0 out of range"),
    (["--mount", "1,2"], "--mount: mount '1,2': expected 6 numbers"),
    (["--out", "c.png"], "unknown point file type"),
])
def test_bad_options_fail_before_reading(tmp_path, capsys, fake_io, extra, match):
    assert main(["register", "bag", "--out", str(tmp_path / "c.ply"), *extra]) == 2
    assert match in capsys.readouterr().err
    assert "read" not in fake_io


def test_existing_output_refused_before_reading(tmp_path, capsys, fake_io):
    out = tmp_path / "c.ply"
    out.write_text("mine")
    assert main(["register", "bag", "--out", str(out)]) == 2
    assert "already exists" in capsys.readouterr().err
    assert "read" not in fake_io
    assert main(["register", "bag", "--out", str(out), "--force"]) == 0
    assert fake_io["write"][2] is True


def test_all_frames_dropped_is_an_error(tmp_path, capsys, fake_io):
    argv = ["register", "bag", "--out", str(tmp_path / "c.ply"), "--crop=100,100,100,101,101,101"]
    assert main(argv) == 2
    assert "all 4 frames dropped (4 empty)" in capsys.readouterr().err
    assert "write" not in fake_io


def test_parse_box_and_format_counts():
    assert parse_box("-1,-2,-3,1,2,3").values() == (-1, -2, -3, 1, 2, 3)
    with pytest.raises(ParameterError, match="expected 6 numbers"):
        parse_box("1,2")
    counts = RegistrationCounts(frames_in=3, frames_dropped_offset=2, points_dropped_crop=7)
    lines = format_counts(counts)
    assert "2 (pose offset)" in lines[0]
    assert "7 (outside crop box)" in lines[1]


REALDATA = realdata_dir()


@pytest.mark.realdata
def test_register_real_ros1_bag_without_poses(tmp_path, capsys):
    bag = REALDATA / "ros1_bag" / "test.bag"
    if not bag.exists():
        pytest.skip(f"{bag} absent")
    out = tmp_path / "luminar.pcd"
    assert main(["register", str(bag), "--out", str(out), "--voxel", "0.5", "--no-pose"]) == 0
    frames = read_frames(bag, ReadSettings(pose_topic="", allow_no_pose=True))
    raw = np.vstack([register_frame(f, frames.mount) for f in frames.frames])
    expected = grid_average(raw, 0.5)
    got = read_points(out)
    assert got.shape == expected.shape
    np.testing.assert_allclose(got, expected, atol=1e-9)  # PCD float64 keeps the order
    text = capsys.readouterr().out
    assert f"points: {len(raw)} in" in text
    assert "frames: 5 in, 5 kept" in text


def test_register_a_point_file_speaks_of_its_rows_and_keeps_its_fields(tmp_path, capsys):
    rng = np.random.default_rng(4)
    points = rng.uniform(-5, 5, (200, 3))
    points[3] = np.nan
    fields = {"intensity": np.arange(200, dtype=np.uint16),
              "label": rng.integers(0, 9, 200).astype(np.int32)}
    source = tmp_path / "scan.npz"
    np.savez(source, points=points, **fields)
    out = tmp_path / "cloud.ply"
    assert main(["register", str(source), "--out", str(out), "--crop=-4,-4,-4,4,4,4"]) == 0
    text = capsys.readouterr().out
    inside = np.all(np.abs(np.nan_to_num(points, nan=9)) <= 4, axis=1)
    assert f"file: {source}: 200 rows; dropped 1 (NaN/inf), {199 - inside.sum()} (outside " \
           f"crop box); {inside.sum()} points out" in text
    assert "fields: kept intensity, label" in text
    assert "scans" not in text and "frames:" not in text
    back = read_points_info(out)
    np.testing.assert_array_equal(back.fields["intensity"], fields["intensity"][inside])
    np.testing.assert_array_equal(back.fields["label"], fields["label"][inside])
    assert main(["register", str(source), "--out", str(tmp_path / "c.xyz")]) == 0
    assert "fields: not kept intensity (plain text holds x y z only)" in capsys.readouterr().out
    assert main(["register", str(source), "--out", str(tmp_path / "v.npz"), "--voxel", "1"]) == 0
    assert "note: fields intensity, label not kept: --voxel averages" in capsys.readouterr().out


def test_register_help_gives_each_odometry_setting_with_its_unit(capsys):
    """A user setting their own IMU's figures reads the units in ``--help``."""
    with pytest.raises(SystemExit):
        main(["register", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "accel_walk: m/s^3/sqrt(Hz); lio: the IMU's accelerometer bias random walk" in text
    assert "gyro_bias: rad/s; lio: the IMU's gyroscope turn-on bias sigma" in text
    assert "voxel: m; map voxel" in text
