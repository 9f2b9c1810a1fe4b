"""Tests for the frame and map specifications."""

from __future__ import annotations

import pytest

from alte.errors import ParameterError
from alte.pipeline import DomainPolicy, FrameSpec, MapSpec, PoseSource
from alte.types import Box


def test_frame_spec_key_names_every_choice() -> None:
    base = FrameSpec(frames=5, voxel=0.2, crop=Box.of((0, 0, 0, 1, 1, 1)))
    assert base.key() == FrameSpec(frames=5, voxel=0.2, crop=Box.of((0, 0, 0, 1, 1, 1))).key()
    others = [FrameSpec(frames=6, voxel=0.2), FrameSpec(frames=5, voxel=0.3),
              FrameSpec(frames=5, voxel=0.2, poses=PoseSource.IDENTITY),
              FrameSpec(frames=5, voxel=0.2, origin=(1.0, 0.0, 0.0))]
    keys = [str(sorted(s.key().items())) for s in [base, *others]]
    assert len(set(keys)) == len(keys)


@pytest.mark.parametrize(("kwargs", "match"), [
    ({"frames": 0}, r"frames=0: expected a positive integer or None"),
    ({"voxel": -1.0}, r"voxel=-1.0 must be a positive finite"),
    ({"max_rate": float("nan")}, r"max_rate=nan must be a positive finite"),
    ({"origin": (0.0, 1.0)}, r"origin"),
])
def test_frame_spec_rejects_bad_values(kwargs: dict[str, object], match: str) -> None:
    with pytest.raises(ParameterError, match=match):
        FrameSpec(**kwargs)  # type: ignore[arg-type]


def test_map_spec_defaults_and_errors() -> None:
    spec = MapSpec("alte2d")
    assert spec.domain is DomainPolicy.AUTO and spec.feed is None and spec.snapshots == 0
    with pytest.raises(ParameterError, match=r"snapshots=-1: expected an integer >= 0"):
        MapSpec("alte2d", snapshots=-1)
