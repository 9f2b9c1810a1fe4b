"""Tests for the frame and map specifications."""

from __future__ import annotations

import pytest

from alte.errors import ParameterError
from alte.pipeline import DomainPolicy, FrameSettings, MapSettings, PoseSource
from alte.registration.odometry import OdometrySettings
from alte.types import Box


def test_frame_spec_key_names_every_choice() -> None:
    base = FrameSettings(frames=5, voxel=0.2, crop=Box.of((0, 0, 0, 1, 1, 1)))
    assert base.key() == FrameSettings(frames=5, voxel=0.2, crop=Box.of((0, 0, 0, 1, 1, 1))).key()
    others = [FrameSettings(frames=6, voxel=0.2), FrameSettings(frames=5, voxel=0.3),
              FrameSettings(frames=5, voxel=0.2, poses=PoseSource.IDENTITY),
              FrameSettings(frames=5, voxel=0.2, origin=(1.0, 0.0, 0.0))]
    keys = [str(sorted(s.key().items())) for s in [base, *others]]
    assert len(set(keys)) == len(keys)


@pytest.mark.parametrize(("kwargs", "match"), [
    ({"frames": 0}, r"frame spec: frames=0 out of range \(frames >= 1\)"),
    ({"frames": True}, r"frame spec: frames=True is not a valid int"),
    ({"voxel": -1.0}, r"frame spec: voxel=-1.0 out of range \(voxel > 0, finite\)"),
    ({"max_rate": float("nan")}, r"frame spec: max_rate=nan must be finite"),
    ({"origin": (0.0, 1.0)}, r"frame spec: origin=\(0.0, 1.0\): expected 3 values"),
    ({"origin": (0.0, 1.0, float("inf"))}, r"frame spec: origin\[2\]=inf must be finite"),
    ({"poses": "gps"}, r"frame spec: poses='gps' out of range \(auto\|recorded\|odometry"),
])
def test_frame_spec_rejects_bad_values(kwargs: dict[str, object], match: str) -> None:
    with pytest.raises(ParameterError, match=match):
        FrameSettings(**kwargs)  # type: ignore[arg-type]


def test_frame_spec_parses_text_and_nested_settings() -> None:
    """A frame spec from text values (a YAML file, a notebook parameter): numbers, the pose
    source by name and the odometry's own record from a mapping, all coerced and checked."""
    spec = FrameSettings.parse({"frames": "5", "voxel": "0.2", "poses": "odometry",
                            "origin": ["1", 2, 3.5], "odometry": {"method": "kiss"}})
    assert spec == FrameSettings(frames=5, voxel=0.2, poses=PoseSource.ODOMETRY,
                             origin=(1.0, 2.0, 3.5), odometry=OdometrySettings(method="kiss"))
    assert spec.key() == FrameSettings(**spec.as_dict()).key()
    with pytest.raises(ParameterError, match=r"frame spec: odometry: odometry: method='icp' "
                                             r"out of range"):
        FrameSettings.parse({"odometry": {"method": "icp"}})
    with pytest.raises(ParameterError, match=r"frame spec: unknown parameter\(s\) frame; "):
        FrameSettings.parse({"frame": 3})


def test_map_spec_defaults_and_errors() -> None:
    spec = MapSettings("alte2d")
    assert spec.domain is DomainPolicy.AUTO and spec.feed is None and spec.snapshots == 0
    with pytest.raises(ParameterError, match=r"map spec: snapshots=-1 out of range"):
        MapSettings("alte2d", snapshots=-1)


def test_map_spec_resolves_the_mapper_and_its_parameters_once() -> None:
    """The class and the parameter record are resolved when the spec is made (an unknown
    mapper or a bad parameter fails before any read), and the map loop builds the mapper
    from that very record."""
    from alte.errors import MapperError
    from alte.mappers import Alte2D, make_mapper
    from alte.mappers.alte2d import Alte2DSettings

    spec = MapSettings("alte2d", {"kappa": "0.5", "max_res": 5})
    assert spec.cls is Alte2D and isinstance(spec.record, Alte2DSettings)
    assert spec.record.as_dict()["kappa"] == 0.5 and spec.params == {"kappa": "0.5",
                                                                     "max_res": 5}
    mapper = make_mapper("alte2d", spec.record)
    assert mapper.params is spec.record  # used as it is, not parsed again
    again = MapSettings("alte2d", spec.record)
    assert again.record is spec.record and again.params == spec.record.as_dict()
    with pytest.raises(MapperError, match="unknown mapper 'kriging'; valid: quadtree"):
        MapSettings("kriging")
    with pytest.raises(ParameterError, match="alte2d: unknown parameter"):
        MapSettings("alte2d", {"max_points": 3})
    with pytest.raises(MapperError, match=r"alte2d: parameters come as a record or as names "
                                          r"and values, not both \(kappa beside the record\)"):
        Alte2D(None, record=spec.record, kappa=1.0)
    with pytest.raises(MapperError, match="alte3d: its parameters are a Alte3DSettings, not a "
                                          "Alte2DSettings"):
        make_mapper("alte3d", {}, record=spec.record)
