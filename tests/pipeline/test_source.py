"""Tests for recognising inputs and streaming their registered frames."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from alte.errors import BagError, PointFileError
from alte.io.points.pointfiles import write_points
from alte.pipeline import FrameSettings, InputKind, StreamCounts, open_input, stream_frames
from alte.sim.scenario import load_metadata
from alte.types import Box


def test_terrain_folder_brings_its_crop_voxel_and_truth(terrain: Path) -> None:
    source = open_input(terrain)
    meta = load_metadata(terrain)
    assert source.kind is InputKind.TERRAIN and source.bag == terrain / "bag"
    resolved = source.resolve(FrameSettings())
    assert resolved.crop == Box.of(meta["crop_box"])
    assert resolved.voxel == meta["registration_voxel"]
    assert source.resolve(FrameSettings(voxel=0.5)).voxel == 0.5  # the caller's choice wins
    truth = source.ground_truth()
    assert truth is not None and truth.bounds == resolved.crop


def test_bag_and_point_file_inputs(bag: Path, tmp_path: Path) -> None:
    source = open_input(bag)
    assert source.kind is InputKind.BAG and source.ground_truth() is None
    assert source.resolve(FrameSettings()) == FrameSettings()  # no crop or voxel of its own
    cloud = write_points(tmp_path / "c.npz", np.random.default_rng(0).normal(size=(50, 3)))
    assert open_input(cloud).kind is InputKind.POINTS


def test_missing_inputs_are_named(tmp_path: Path) -> None:
    with pytest.raises(BagError, match=r"bag .*nothing does not exist \(nor a terrain folder"):
        open_input(tmp_path / "nothing")
    with pytest.raises(PointFileError, match=r"gone\.ply: no such point file"):
        open_input(tmp_path / "gone.ply")


def test_frames_stream_one_at_a_time_with_counts(terrain: Path) -> None:
    source = open_input(terrain)
    spec = source.resolve(FrameSettings(frames=3))
    counts = StreamCounts()
    stream = stream_frames(source, spec, counts)
    first = next(stream)
    assert counts.registration.frames_kept == 1  # nothing read ahead
    rest = list(stream)
    assert counts.selected == 3 and counts.scans == 4 and len(rest) == 2
    stamps = [first.stamp, *(f.stamp for f in rest)]
    assert stamps == sorted(stamps)
    for frame in (first, *rest):
        assert spec.crop is not None
        assert ((frame.points >= spec.crop.lo) & (frame.points <= spec.crop.hi)).all()


def test_point_file_is_one_cropped_frame(tmp_path: Path) -> None:
    path = tmp_path / "c.xyz"
    path.write_text("0 0 0\n5 5 5\nnan 0 0\n")
    counts = StreamCounts()
    spec = FrameSettings(crop=Box.of((-1, -1, -1, 1, 1, 1)), origin=(0.0, 0.0, 10.0))
    frames = list(stream_frames(open_input(path), spec, counts))
    assert len(frames) == 1 and frames[0].points.tolist() == [[0.0, 0.0, 0.0]]
    assert frames[0].origin.tolist() == [0.0, 0.0, 10.0]
    assert counts.registration.points_dropped_crop == 1
    assert counts.read.points_nonfinite == 1
