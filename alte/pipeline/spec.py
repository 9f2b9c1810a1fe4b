"""What a map run is asked to do: which frames and how they are registered, which map.

A :class:`FrameSpec` fixes everything that decides the registered frames (frame
selection, voxel, crop, mount, topics, pose source, manoeuvre filter): two runs with
equal frame specs on one input share their registration (the cache key). A
:class:`MapSpec` names the mapper, its parameters, the domain policy and the feed.
``None`` means "the input's own": a terrain folder brings its control volume (crop
and domain) and its registration voxel; a bag or point file brings neither.
"""

from __future__ import annotations

import enum
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from alte.errors import ParameterError
from alte.mappers import MapperClass, mapper_class
from alte.mappers.base import Feed
from alte.mappers.domain import Domain
from alte.params import Record
from alte.registration.grid import check_voxel
from alte.registration.odometry import OdometryParams
from alte.types import Box, Mount

__all__ = ["DomainChoice", "DomainPolicy", "FrameSpec", "MapSpec", "PoseSource"]


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


@dataclass(frozen=True)
class FrameSpec:
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

    frames: int | None = None
    voxel: float | None = None
    crop: Box | None = None
    mount: Mount | None = None
    cloud_topic: str | None = None
    pose_topic: str | None = None
    poses: PoseSource = PoseSource.AUTO
    max_rate: float | None = None
    max_offset: float | None = None
    origin: tuple[float, float, float] = (0.0, 0.0, 0.0)
    odometry: OdometryParams = field(default_factory=OdometryParams)
    deskew: bool = True
    pose_file: Path | None = None

    def __post_init__(self) -> None:
        if self.frames is not None and (isinstance(self.frames, bool)
                                        or not isinstance(self.frames, int) or self.frames < 1):
            raise ParameterError(f"frames={self.frames!r}: expected a positive integer or None")
        if self.voxel is not None:
            object.__setattr__(self, "voxel", check_voxel(self.voxel))
        for name in ("max_rate", "max_offset"):
            value = getattr(self, name)
            if value is not None and not (np.isfinite(value) and value > 0):
                raise ParameterError(f"{name}={value!r} must be a positive finite number")
        origin = np.asarray(self.origin, dtype=np.float64).reshape(-1)
        if origin.shape != (3,) or not np.isfinite(origin).all():
            raise ParameterError(f"origin {self.origin!r}: expected 3 finite numbers x,y,z")
        object.__setattr__(self, "origin", tuple(float(v) for v in origin))
        if self.pose_file is not None:
            object.__setattr__(self, "pose_file", Path(self.pose_file))
            if self.pose_topic:
                raise ParameterError("--pose-file and --pose-topic exclude each other")

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
class MapSpec:
    """Which map: mapper name and parameters, domain (or policy), feed, time-lapse.

    ``feed`` None uses the mapper's own protocol (``Mapper.default_feed``: the thesis
    built Quadtree once on the final cloud and fed the others frame by frame);
    ``snapshots`` keeps the cells that many times over the run (time-lapse figures)
    and counts the basis functions after every frame. The mapper's class (``cls``) and
    its parameter record (``record``) are resolved here, once: an unknown mapper or a
    bad parameter fails before any input is read.
    """

    mapper: str
    params: Mapping[str, object] | Record = field(default_factory=dict)
    domain: Domain | DomainPolicy = DomainPolicy.AUTO
    feed: Feed | None = None
    snapshots: int = 0
    cls: MapperClass = field(init=False, repr=False, compare=False)
    record: Record = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        if isinstance(self.snapshots, bool) or not isinstance(self.snapshots, int) \
                or self.snapshots < 0:
            raise ParameterError(f"snapshots={self.snapshots!r}: expected an integer >= 0")
        cls = mapper_class(self.mapper)
        given = self.params
        record = given if isinstance(given, cls.Params) else cls.Params.parse(
            given.as_dict() if isinstance(given, Record) else given)
        object.__setattr__(self, "cls", cls)
        object.__setattr__(self, "record", record)
        object.__setattr__(self, "params", given.as_dict() if isinstance(given, Record)
                           else dict(given))
