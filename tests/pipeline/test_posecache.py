"""Odometry's pose cache (alte.pipeline.posecache): aligned once, read back the same."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from alte.pipeline import (
    FrameSettings,
    PoseSource,
    StreamCounts,
    open_input,
    posecache,
    stream_frames,
)
from alte.registration.odometry import OdometrySettings
from alte.types import RegisteredFrame


def _run(folder: Path, spec: FrameSettings, cache: Path | None,
         ) -> tuple[list[RegisteredFrame], StreamCounts]:
    source = open_input(folder)
    counts = StreamCounts()
    frames = list(stream_frames(source, source.resolve(spec), counts, pose_cache=cache))
    return frames, counts


def _same(mine: list[RegisteredFrame], theirs: list[RegisteredFrame]) -> None:
    assert [f.stamp for f in mine] == [f.stamp for f in theirs]
    for a, b in zip(mine, theirs, strict=True):
        np.testing.assert_array_equal(a.position, b.position)
        np.testing.assert_array_equal(a.quaternion, b.quaternion)
        np.testing.assert_array_equal(a.points, b.points)


def test_lio_poses_are_aligned_once_and_read_back_for_another_selection(
        uav_first_scans: Path, tmp_path: Path) -> None:
    """The first run (2 of 4 scans kept) aligns every scan and keeps them; a run over all
    4 then reads them, and both give what an uncached run gives, counts included (the
    mission's first 4 scans: consecutive, the IMU between them is 0.3 s to integrate)."""
    uav = uav_first_scans
    cache = tmp_path / "poses"
    spec = FrameSettings(poses=PoseSource.ODOMETRY, odometry=OdometrySettings(method="lio"))
    some, first = _run(uav, replace(spec, frames=2), cache)
    assert len(list(cache.iterdir())) == 1
    every, again = _run(uav, spec, cache)
    plain_some, _ = _run(uav, replace(spec, frames=2), None)
    plain, alone = _run(uav, spec, None)
    _same(some, plain_some)
    _same(every, plain)
    assert (first.poses.method, first.poses.frames) == ("lio", 4)
    assert again.poses.as_dict() == first.poses.as_dict()
    assert (again.poses.deskewed, again.read.frames) == (alone.poses.deskewed, alone.read.frames)
    assert any("read from the pose cache" in n for n in again.notes)
    assert not any("pose cache" in n for n in first.notes + alone.notes)


def test_the_key_follows_the_settings_the_input_and_the_code(
        terrain: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Other odometry settings, another input or other odometry code: another key; the
    frame selection, crop and voxel (registration, after the poses) keep it."""
    identity = open_input(terrain).identity
    spec = FrameSettings(poses=PoseSource.ODOMETRY)
    params = OdometrySettings(method="kiss")
    key = posecache.pose_key(identity, spec, params)
    assert posecache.pose_key(identity, replace(spec, frames=2, voxel=0.5), params) == key
    assert posecache.pose_key(identity, spec, replace(params, window=0)) != key
    assert posecache.pose_key(identity, replace(spec, deskew=False), params) != key
    assert posecache.pose_key("another input", spec, params) != key
    monkeypatch.setattr(posecache, "code_hash", lambda: "changed code")
    assert posecache.pose_key(identity, spec, params) != key


def test_an_unfinished_run_leaves_no_cache(terrain: Path, tmp_path: Path) -> None:
    """A consumer that stops early (a killed run) keeps nothing: only a run that posed
    every scan is cached, and the next run aligns again."""
    cache = tmp_path / "poses"
    spec = FrameSettings(poses=PoseSource.ODOMETRY, odometry=OdometrySettings(method="kiss"))
    source = open_input(terrain)
    frames = stream_frames(source, source.resolve(spec), StreamCounts(), pose_cache=cache)
    next(frames)
    frames.close()
    assert not cache.exists() or not [p for p in cache.iterdir() if not p.name.startswith(".")]
    _, counts = _run(terrain, spec, cache)
    assert counts.poses.frames == 4
    assert not any("pose cache" in n for n in counts.notes)


def test_a_cache_that_lacks_a_scan_is_refused(terrain: Path, tmp_path: Path) -> None:
    """A cached run whose stamps do not match the bag's scans (a damaged cache) raises a
    PoseError that says which folder to delete, never poses from the wrong scan."""
    from alte.errors import PoseError

    cache = tmp_path / "poses"
    spec = FrameSettings(poses=PoseSource.ODOMETRY, odometry=OdometrySettings(method="kiss"))
    _run(terrain, spec, cache)
    (folder,) = cache.iterdir()
    with np.load(folder / "arrays.npz") as arrays:
        kept = {k: arrays[k] for k in arrays.files}
    np.savez(folder / "arrays.npz", **(kept | {"stamps": kept["stamps"] + 1}))
    with pytest.raises(PoseError, match=r"pose cache: no posed scan at stamp \d+; delete"):
        _run(terrain, spec, cache)
