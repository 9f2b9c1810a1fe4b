"""What ``scenario.json`` holds that the pipeline reads, as types."""

from __future__ import annotations

from typing import NotRequired, TypedDict

__all__ = ["SCENARIO_FILE", "MountMeta", "ScenarioMeta"]

#: The file of a terrain folder that describes it.
SCENARIO_FILE = "scenario.json"


class MountMeta(TypedDict):
    """A sensor mount in ``scenario.json``: offset (m), quaternion (x, y, z, w) and the
    ``--mount`` string ``x,y,z,roll,pitch,yaw``."""

    translation: list[float]
    quaternion: list[float]
    xyz_rpy_deg: str


class ScenarioMeta(TypedDict):
    """What the pipeline reads of ``scenario.json`` (:func:`load_metadata` checks these keys
    are there; the file holds more: the spec, sensor, counts, files, ...)."""

    name: str
    case: str
    bag: str
    crop_box: list[float]
    registration_voxel: float
    mount: MountMeta
    title: NotRequired[str]
