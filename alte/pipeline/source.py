"""Inputs of the pipeline and the live stream of registered frames they give.

An input is a ROS bag (file or folder), a simulated terrain folder (``scenario.json``
+ ``bag/`` + ``ground_truth.ply``: it brings its control volume and registration
voxel) or a point file (one frame, sensor at ``FrameSettings.origin``).
:func:`stream_frames` turns an input and a :class:`~alte.pipeline.spec.FrameSettings`
into registered frames one at a time: read -> pose -> eq. 2.2 -> crop -> grid
average, with the merged cloud accumulated on the side when asked.
"""

from __future__ import annotations

import enum
import hashlib
import json
from collections.abc import Iterator
from dataclasses import dataclass, field, replace
from functools import cached_property
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from alte.errors import BagError, ParameterError, PointFileError, TopicError
from alte.io.bags.bag import NO_POSE_NOTE, FrameStream, ReadCounts, ReadSettings
from alte.io.poses.pose import POSE_TYPES
from alte.pipeline.posing import odometry_poses
from alte.pipeline.spec import FrameSettings, PoseSource
from alte.registration.deskew import DeskewCounts, deskew_frames
from alte.registration.grid import GridAccumulator, grid_average
from alte.registration.odometry import KEYS, PoseCounts, refine_frames
from alte.registration.register import RegistrationCounts, crop_mask, register_frames
from alte.types import Box, Frame, RegisteredFrame

if TYPE_CHECKING:
    from alte.metrics.maps import GroundTruth

__all__ = ["InputKind", "Source", "StreamCounts", "open_input", "stream_frames"]

SCENARIO_FILE = "scenario.json"


class InputKind(enum.Enum):
    """What an input path holds."""

    BAG = "bag"
    TERRAIN = "terrain"
    POINTS = "points"


@dataclass(frozen=True)
class Source:
    """An input: its path and kind, and for a terrain folder its bag and control volume."""

    path: Path
    kind: InputKind
    bag: Path | None = None
    control: Box | None = None
    voxel: float | None = None
    name: str = ""
    title: str = ""

    def resolve(self, spec: FrameSettings) -> FrameSettings:
        """``spec`` with the input's own crop and voxel where it leaves them unset."""
        return replace(spec, crop=spec.crop if spec.crop is not None else self.control,
                       voxel=spec.voxel if spec.voxel is not None else self.voxel)

    @cached_property
    def identity(self) -> str:
        """What the input's content is, for cache keys: sizes and times of its files."""
        files = [self.path] if self.path.is_file() else sorted(
            p for p in self.path.rglob("*") if p.is_file())
        stats = [(p.relative_to(self.path.parent).as_posix(), p.stat().st_size,
                  p.stat().st_mtime_ns) for p in files]
        return hashlib.sha256(json.dumps(stats).encode()).hexdigest()

    def ground_truth(self) -> GroundTruth | None:
        """The true surface and control volume of a simulated terrain (None otherwise)."""
        if self.kind is not InputKind.TERRAIN or self.control is None:
            return None
        from alte.metrics.maps import GroundTruth
        from alte.metrics.surface import TrueSurface
        from alte.sim.groundtruth import load_ground_truth

        scene = load_ground_truth(self.path)
        surface = TrueSurface(scene.vertices, scene.triangles, scene.object_ids,
                              {i: o.name for i, o in enumerate(scene.objects)},
                              {i: o.cls for i, o in enumerate(scene.objects)})
        return GroundTruth(surface, self.control)


def open_input(path: str | Path) -> Source:
    """Recognise ``path``: terrain folder, ROS bag (file or folder) or point file."""
    from alte.io.points.pointfiles import READ_SUFFIXES

    where = Path(path)
    if not where.exists():
        if where.name.lower().endswith(READ_SUFFIXES):
            raise PointFileError(f"{where}: no such point file")
        raise BagError(f"bag {where} does not exist (nor a terrain folder or point file)")
    if where.is_dir() and (where / SCENARIO_FILE).is_file():
        return _terrain(where)
    if where.is_file() and where.name.lower().endswith(READ_SUFFIXES):
        return Source(where, InputKind.POINTS, name=where.stem)
    return Source(where, InputKind.BAG, bag=where, name=where.stem)


def _terrain(folder: Path) -> Source:
    from alte.sim.scenario import load_metadata

    meta = load_metadata(folder)
    return Source(folder, InputKind.TERRAIN, bag=folder / str(meta["bag"]),
                  control=Box.of(meta["crop_box"]), voxel=float(meta["registration_voxel"]),
                  name=str(meta["name"]), title=str(meta.get("title", meta["name"])))


@dataclass
class StreamCounts:
    """What reading and registration kept and dropped (updated while frames stream)."""

    read: ReadCounts = field(default_factory=ReadCounts)
    registration: RegistrationCounts = field(default_factory=RegistrationCounts)
    scans: int = 0
    selected: int = 0
    notes: list[str] = field(default_factory=list)
    poses: PoseCounts = field(default_factory=PoseCounts)
    deskew: DeskewCounts = field(default_factory=DeskewCounts)

    def as_dict(self) -> dict[str, object]:
        """JSON-ready form."""
        return {"scans": self.scans, "selected": self.selected, "read": self.read.as_dict(),
                "registration": self.registration.as_dict(), "notes": list(self.notes),
                "poses": self.poses.as_dict(), "deskew": self.deskew.as_dict()}


def _open(source: Source, spec: FrameSettings, pose_topic: str | None, progress: bool,
          read_all: bool = False) -> FrameStream:
    pose_file = spec.pose_file if pose_topic != "" else None
    options = ReadSettings(cloud_topic=spec.cloud_topic, pose_topic=pose_topic,
                          allow_no_pose=True, frames=spec.frames, progress=progress,
                          pose_file=pose_file)
    return FrameStream(source.bag or source.path, options, mount=spec.mount,
                       read_all=read_all)


def _deskewed(stream: FrameStream, spec: FrameSettings, counts: DeskewCounts) -> Iterator[Frame]:
    """The stream's frames, deskewed along its pose track when ``spec.deskew`` (clouds
    with per-point time), else as read (their time dropped: registered as taken)."""
    if spec.deskew and stream.track is not None:
        return deskew_frames(iter(stream), stream.track, stream.mount, counts=counts,
                             max_gap_s=stream.options.max_gap_s)
    return (replace(f, times=None) for f in stream)


def _posed(source: Source, spec: FrameSettings, counts: PoseCounts, progress: bool,
           deskew: DeskewCounts | None = None, *, pose_cache: Path | None = None,
           ) -> tuple[FrameStream, Iterator[Frame]]:
    """The scan stream and its frames posed as ``spec.poses`` says (:class:`PoseSource`);
    odometry keeps its poses in ``pose_cache`` (:mod:`alte.pipeline.posecache`)."""
    deskew = DeskewCounts() if deskew is None else deskew
    choice = spec.poses
    counts.source = choice.value
    if choice is PoseSource.IDENTITY:
        stream = _open(source, spec, "", progress)
        return stream, iter(stream)
    probe = _open(source, spec, spec.pose_topic, progress)
    if choice in (PoseSource.RECORDED, PoseSource.REFINE) and probe.track is None:
        raise TopicError(f"{probe.path}: poses={choice.value} needs the bag's poses and it "
                         f"has no pose topic ({', '.join(POSE_TYPES)}) for "
                         f"{probe.cloud_topic}; use poses=odometry (LiDAR odometry) or "
                         "poses=identity (static sensor)", setting="frame spec.poses")
    if choice is PoseSource.RECORDED:
        return probe, _deskewed(probe, spec, deskew)
    if choice is PoseSource.REFINE:
        counts.method = "refine"
        counts.settings = {k: spec.odometry.as_dict()[k] for k in KEYS["refine"]}
        return probe, refine_frames(_deskewed(probe, spec, deskew), probe.mount, counts=counts,
                                    params=spec.odometry)
    if choice is PoseSource.AUTO and probe.track is not None:
        counts.source = PoseSource.RECORDED.value
        return probe, _deskewed(probe, spec, deskew)
    counts.source = PoseSource.ODOMETRY.value
    # Odometry reads every scan (it cannot align scans seconds apart); only the scans
    # ``spec.frames`` selects go on to registration.
    every = probe.track is None and probe.selection is None
    stream = probe if every else _open(source, spec, "", progress, read_all=True)
    stream.notes[:] = [n for n in stream.notes if n != NO_POSE_NOTE]
    if stream.read_all:
        stream.notes.append(f"odometry over all {stream.scans} scans; {stream.selected} of "
                            "them (evenly spaced) registered")
    cache = None if pose_cache is None else (pose_cache, source.identity)
    return stream, odometry_poses(stream, probe, spec, counts, cache)


def _bag_frames(source: Source, spec: FrameSettings, counts: StreamCounts,
                merge: GridAccumulator | None, progress: bool, *,
                pose_cache: Path | None) -> Iterator[RegisteredFrame]:
    stream, posed = _posed(source, spec, counts.poses, progress, counts.deskew,
                           pose_cache=pose_cache)
    counts.scans, counts.selected, counts.notes = stream.scans, stream.selected, stream.notes
    frames = register_frames(posed, stream.mount, voxel=spec.voxel,
                             crop_box=None if spec.crop is None else spec.crop.values(),
                             max_rate=spec.max_rate, max_offset=spec.max_offset,
                             counts=counts.registration, merge=merge)
    for frame, points, origin in frames:
        counts.read = stream.counts
        yield RegisteredFrame(frame.stamp, points, origin, np.asarray(frame.position),
                              np.asarray(frame.quaternion))
    counts.read = stream.counts


def _file_frames(source: Source, spec: FrameSettings, counts: StreamCounts,
                 merge: GridAccumulator | None) -> Iterator[RegisteredFrame]:
    """A point file as one frame: finite, cropped, grid-averaged, seen from ``spec.origin``;
    the file's other fields ride along while every point is kept (no voxel)."""
    from alte.io.points.pointfiles import read_points_info

    if spec.poses in (PoseSource.ODOMETRY, PoseSource.REFINE):
        raise ParameterError(f"{source.path}: poses={spec.poses.value} needs a bag of scans; "
                             "a point file is one frame seen from its origin",
                             setting="frame spec.poses")
    counts.poses.source = "origin"
    info = read_points_info(source.path)
    reg = counts.registration
    counts.scans = counts.selected = counts.read.scans_read = counts.read.frames = 1
    counts.read.points_nonfinite = info.nonfinite
    points, fields = info.points, info.fields
    reg.frames_in, reg.points_in = 1, len(points)
    if spec.crop is not None:
        inside = crop_mask(points, spec.crop.values())
        reg.points_dropped_crop = int(len(points) - np.count_nonzero(inside))
        points, fields = points[inside], {k: v[inside] for k, v in fields.items()}
    if len(points) == 0:
        reg.frames_dropped_empty = 1
        return
    if merge is not None:
        merge.add(points)
    if spec.voxel is not None:
        points = grid_average(points, spec.voxel)
        if fields:
            counts.notes.append(f"fields {', '.join(fields)} not kept: --voxel averages the "
                                "points into cells")
    reg.frames_kept, reg.points_registered = 1, len(points)
    origin = np.array(spec.origin)
    yield RegisteredFrame(0, points, origin, origin.copy(), np.array([0.0, 0.0, 0.0, 1.0]),
                          fields if spec.voxel is None else None)


def stream_frames(source: Source, spec: FrameSettings, counts: StreamCounts, *,
                  merge: GridAccumulator | None = None, progress: bool = False,
                  pose_cache: Path | None = None) -> Iterator[RegisteredFrame]:
    """Registered frames of ``source`` one at a time (``spec`` already resolved).

    ``merge`` receives every frame's raw cropped points (the thesis' box-grid merge);
    ``pose_cache``: a folder where odometry keeps the poses it aligned, per input and
    settings, and reads them back (:mod:`alte.pipeline.posecache`).
    """
    if source.kind is InputKind.POINTS:
        return _file_frames(source, spec, counts, merge)
    return _bag_frames(source, spec, counts, merge, progress, pose_cache=pose_cache)
