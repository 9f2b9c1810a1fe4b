"""What a map run is asked to do: which frames and how they are registered, which map.

A :class:`FrameSettings` fixes everything that decides the registered frames (frame
selection, voxel, crop, mount, topics, pose source, manoeuvre filter): two runs with
equal frame specs on one input share their registration (the cache key). A
:class:`MapSettings` names the mapper, its parameters, the domain policy and the feed.
``None`` means "the input's own": a terrain folder brings its control volume (crop
and domain) and its registration voxel; a bag or point file brings neither.
"""

from __future__ import annotations

import enum
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import ClassVar, cast

import numpy as np

from alte.errors import ParameterError
from alte.mappers.base import Feed, Mapper
from alte.mappers.domain import Domain
from alte.params import Record, param
from alte.registration.grid import VOXEL
from alte.registration.odometry import OdometrySettings
from alte.types import Box, Mount

__all__ = ["DomainChoice", "DomainPolicy", "FrameSettings", "MapSettings", "PoseSource"]


class DomainPolicy(enum.Enum):
    """Where a map's root cell comes from when no explicit :class:`Domain` is given.

    ``AUTO``: the control volume when the input has one (a terrain folder), else the
    data. ``CONTROL``: the cube over the control volume (thesis 3.3: "an overall domain
    is defined"). ``DATA``: the cube over the registered points the map receives
    (found by a first pass over the frames when they are streamed).
    """

    AUTO = "auto"
    CONTROL = "control"
    DATA = "data"


class DomainChoice(enum.StrEnum):
    """Where a run's root cell came from (the resolved :class:`DomainPolicy`, in the run's
    summary): none for a mapper with a fixed key space, the caller's explicit domain, the
    control volume or the data."""

    NONE = "none (fixed key space)"
    EXPLICIT = "explicit"
    CONTROL = "control"
    DATA = "data"


class PoseSource(enum.Enum):
    """Where each scan's pose comes from.

    ``AUTO``: the bag's pose topic, or LiDAR odometry when it has none (noted in the
    counts). ``RECORDED``: the pose topic (an error without one). ``ODOMETRY``: KISS-ICP
    over the scans, anchored at the recorded pose of the first scan when there is one.
    ``REFINE``: the recorded poses aligned scan-to-map. ``IDENTITY``: none (static sensor).
    """

    AUTO = "auto"
    RECORDED = "recorded"
    ODOMETRY = "odometry"
    REFINE = "refine"
    IDENTITY = "identity"


def _file_identity(path: Path | None) -> list[object] | None:
    """A file's path, size and modification time (a cache key changes with its content)."""
    if path is None:
        return None
    stat = path.stat() if path.is_file() else None
    return [str(path.resolve()), stat.st_size if stat else 0, stat.st_mtime_ns if stat else 0]


def _positive(value: float) -> bool:
    return bool(np.isfinite(value) and value > 0)


def _finite(values: tuple[float, ...]) -> bool:
    return bool(np.isfinite(values).all())


@dataclass(frozen=True)
class FrameSettings(Record):
    """How the input becomes registered frames (module docstring).

    ``frames``: at most that many scans, evenly spaced over the cloud topic (None: all);
    ``voxel`` (m): per-frame grid average and the merged cloud's box grid; ``crop``:
    the control volume points are kept in; ``origin``: the sensor position of a point
    file; ``max_rate`` (rad/s) / ``max_offset`` (s): the fast-manoeuvre filter;
    ``odometry``: how odometry and refinement align scans (``poses`` odometry, refine);
    ``deskew``: move the points of a cloud with per-point time to its stamp with the
    sensor's motion (:mod:`alte.registration.deskew`; False: register them as taken).
    ``pose_file``: poses from a TUM file (``t x y z qx qy qz qw``) instead of a topic.
    """

    OWNER: ClassVar[str] = "frame spec"
    frames: int | None = param(None, lambda v: v >= 1, "frames >= 1",
                               "scans kept, evenly spaced (None: all)")
    voxel: float | None = field(default=None, metadata={"rule": VOXEL})
    crop: Box | None = param(None, help="the control volume points are kept in")
    mount: Mount | None = param(None, help="the sensor's mount on the vehicle")
    cloud_topic: str | None = param(None, help="the bag's point cloud topic")
    pose_topic: str | None = param(None, help="the bag's pose topic")
    poses: PoseSource = param(PoseSource.AUTO, help="where each scan's pose comes from")
    max_rate: float | None = param(None, _positive, "max_rate > 0, finite",
                                   "fast-manoeuvre filter: angular rate (rad/s)")
    max_offset: float | None = param(None, _positive, "max_offset > 0, finite",
                                     "fast-manoeuvre filter: pose-to-scan offset (s)")
    origin: tuple[float, float, float] = param((0.0, 0.0, 0.0), _finite, "finite x,y,z",
                                               "the sensor position of a point file (m)")
    odometry: OdometrySettings = field(default_factory=OdometrySettings)
    deskew: bool = param(True, help="deskew clouds that carry per-point time")
    pose_file: Path | None = param(None, help="poses from a TUM file")

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.pose_file is not None and self.pose_topic:
            raise ParameterError(f"{self.OWNER}: pose_file and pose_topic exclude each other",
                                 setting=(f"{self.OWNER}.pose_file", f"{self.OWNER}.pose_topic"))

    def key(self) -> dict[str, object]:
        """Everything that decides the registered frames, JSON-ready (the cache key)."""
        return {"frames": self.frames, "voxel": self.voxel,
                "crop": None if self.crop is None else list(self.crop.values()),
                "mount": None if self.mount is None else self.mount.to_string(),
                "cloud_topic": self.cloud_topic, "pose_topic": self.pose_topic,
                "poses": self.poses.value, "max_rate": self.max_rate,
                "max_offset": self.max_offset, "origin": list(self.origin),
                "odometry": self.odometry.as_dict(), "deskew": self.deskew,
                "pose_file": _file_identity(self.pose_file)}


@dataclass(frozen=True)
class MapSettings(Record):
    """Which map: mapper and parameters, domain (or policy), feed, time-lapse.

    ``mapper`` is a mapper class or a name the registry resolves
    (:mod:`alte.mappers.registry`); once made, ``mapper`` holds the name and ``cls`` the
    class. ``feed`` None uses the mapper's own protocol (``Mapper.default_feed``: the thesis
    built Quadtree once on the final cloud and fed the others frame by frame);
    ``snapshots`` keeps the cells that many times over the run (time-lapse figures)
    and counts the basis functions after every frame. The mapper's class (``cls``) and
    its parameter record (``record``) are resolved here, once: an unknown mapper or a
    bad parameter fails before any input is read.
    """

    OWNER: ClassVar[str] = "map spec"
    mapper: type[Mapper] | str
    params: Mapping[str, object] | Record = field(default_factory=dict)
    domain: Domain | DomainPolicy = DomainPolicy.AUTO
    feed: Feed | None = None
    snapshots: int = param(0, lambda v: v >= 0, "snapshots >= 0",
                           "cell snapshots kept over the run (time-lapse figures)")
    record: Record = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        super().__post_init__()
        if not isinstance(self.mapper, str):  # a class: kept, and its name is the mapper
            object.__setattr__(self, "_cls", self.mapper)
            object.__setattr__(self, "mapper", self.mapper.name)
        cls = self.cls
        given = self.params
        record = given if isinstance(given, cls.Settings) else cls.Settings.parse(
            given.as_dict() if isinstance(given, Record) else given)
        object.__setattr__(self, "record", record)
        object.__setattr__(self, "params", given.as_dict() if isinstance(given, Record)
                           else dict(given))

    @property
    def cls(self) -> type[Mapper]:
        """The mapper's class: the one given, or the registry's for the name (the registry,
        and with it the mappers' kernels, loads on first use: a spec is light to import)."""
        found = self.__dict__.get("_cls")
        if found is None:
            from alte.mappers import registry

            found = registry.resolve(str(self.mapper))
            object.__setattr__(self, "_cls", found)
        return cast("type[Mapper]", found)
