"""Tests for registering an input once: the disk cache and the merged cloud."""

from __future__ import annotations

import importlib
from pathlib import Path

import numpy as np
import pytest

from alte.errors import RegistrationError
from alte.pipeline import FrameSettings, merged_cloud, open_input, prepare
from alte.types import Box


def test_cached_registration_equals_the_streamed_one(terrain: Path, tmp_path: Path) -> None:
    source = open_input(terrain)
    fresh = prepare(source, FrameSettings(frames=3))
    cached = prepare(source, FrameSettings(frames=3), cache=tmp_path)
    assert isinstance(cached.points, np.memmap) and cached.key == fresh.key
    np.testing.assert_array_equal(cached.points, fresh.points)
    np.testing.assert_array_equal(cached.offsets, fresh.offsets)
    np.testing.assert_array_equal(cached.cloud, fresh.cloud)
    np.testing.assert_array_equal(cached.trajectory.origins, fresh.trajectory.origins)
    assert cached.counts == fresh.counts and len(cached) == 3
    np.testing.assert_array_equal(cached.frame(1).points,
                                  fresh.points[fresh.offsets[1]:fresh.offsets[2]])


def test_cache_is_reused_and_keyed_by_spec(terrain: Path, tmp_path: Path,
                                           monkeypatch: pytest.MonkeyPatch) -> None:
    source = open_input(terrain)
    first = prepare(source, FrameSettings(frames=2), cache=tmp_path)

    def no_read(*args: object, **kwargs: object) -> None:
        raise AssertionError("registered again")

    monkeypatch.setattr(importlib.import_module("alte.pipeline.prepare"), "stream_frames",
                        no_read)
    again = prepare(source, FrameSettings(frames=2), cache=tmp_path)
    np.testing.assert_array_equal(again.points, first.points)
    with pytest.raises(AssertionError, match="registered again"):
        prepare(source, FrameSettings(frames=2, voxel=0.5), cache=tmp_path)
    assert len(list(tmp_path.iterdir())) == 1


def test_merged_cloud_is_the_box_grid_of_every_frame(terrain: Path) -> None:
    source = open_input(terrain)
    cloud, counts = merged_cloud(source, FrameSettings(frames=3))
    reg = prepare(source, FrameSettings(frames=3))
    np.testing.assert_array_equal(cloud, reg.cloud)
    assert counts.registration.points_out == len(cloud) <= len(reg.points)


def test_nothing_left_is_an_error(terrain: Path) -> None:
    far = FrameSettings(crop=Box.of((1e3, 1e3, 1e3, 1e3 + 1, 1e3 + 1, 1e3 + 1)))
    with pytest.raises(RegistrationError, match=r"all 4 frames dropped \(4 empty\)"):
        prepare(open_input(terrain), far)
    with pytest.raises(RegistrationError, match=r"all 4 frames dropped"):
        merged_cloud(open_input(terrain), far)
