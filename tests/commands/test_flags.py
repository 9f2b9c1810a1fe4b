"""The library names a setting, the command line its flag (:mod:`alte.commands.flags`)."""

from __future__ import annotations

import pickle

import pytest

from alte.commands.flags import FLAGS, flag_message, flags_of
from alte.errors import AlteError, ParameterError
from alte.pipeline import FrameSettings
from alte.registration.grid import VOXEL, GridSettings, check_voxel


def test_a_setting_becomes_the_flag_the_command_has() -> None:
    err = ParameterError("read: pose_file and pose_topic exclude each other",
                         setting=("read.pose_file", "read.pose_topic"))
    assert flag_message(err, {"--pose-file", "--pose-topic"}) == (
        "--pose-file, --pose-topic: read: pose_file and pose_topic exclude each other")
    assert flags_of(err, {"--pose-topic"}) == ["--pose-topic"]
    # a command without the flag, or an error naming no setting: the message as it is
    assert flag_message(err, {"--out"}) == str(err)
    assert flag_message(AlteError("plain"), set(FLAGS.values())) == "plain"
    # the settings survive pickling (errors cross Dask workers)
    assert pickle.loads(pickle.dumps(err)).settings == err.settings


def test_a_record_error_names_its_setting() -> None:
    with pytest.raises(ParameterError, match=r"^frame spec: frames=0 out of range") as caught:
        FrameSettings(frames=0)
    assert caught.value.settings == ("frame spec.frames",)
    with pytest.raises(ParameterError, match="must be finite") as caught:
        FrameSettings(voxel=float("nan"))
    assert caught.value.settings == ("frame spec.voxel",)


def test_one_voxel_rule() -> None:
    """``FrameSettings.voxel`` and the registration grid's ``check_voxel`` apply one rule."""
    with pytest.raises(ParameterError, match=r"^grid: voxel=0.0 out of range \(voxel > 0, "
                                             r"finite\)$"):
        check_voxel(0.0)
    with pytest.raises(ParameterError, match=r"^frame spec: voxel=-1.0 out of range "
                                             r"\(voxel > 0, finite\)$"):
        FrameSettings(voxel=-1.0)
    spec_rule = next(f for f in FrameSettings.__dataclass_fields__.values() if f.name == "voxel")
    grid_rule = GridSettings.__dataclass_fields__["voxel"]
    assert spec_rule.metadata["rule"] is VOXEL is grid_rule.metadata["rule"]
    assert check_voxel(0.25) == 0.25
