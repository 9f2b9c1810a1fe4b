"""Registered frames kept for reuse: in memory, or in an on-disk cache read back lazily.

:func:`prepare` registers an input once per :class:`~alte.pipeline.spec.FrameSettings`:
every frame's points laid end to end (``points`` and ``offsets``), the trajectory, the
merged cloud (set A of the thesis' metrics) and the counts. With ``cache=DIR`` the
result is written to ``DIR/<key>/`` (key: the input's identity and the frame spec)
while the frames stream, and later calls memory-map it, so several maps of one input
(a sweep, a chapter's table) register it once and never hold it all in memory.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Iterator
from contextlib import ExitStack
from dataclasses import dataclass
from pathlib import Path
from typing import BinaryIO

import numpy as np
from numpy.typing import NDArray

from alte import __version__
from alte.errors import AlteError, RegistrationError
from alte.fsutil import atomic_dir
from alte.io.bags.bag import ReadCounts
from alte.io.points.pcd import Fields
from alte.pipeline.source import Source, StreamCounts, stream_frames
from alte.pipeline.spec import FrameSettings
from alte.registration.deskew import DeskewCounts
from alte.registration.grid import GridAccumulator
from alte.registration.odometry import PoseCounts
from alte.registration.register import RegistrationCounts, empty_reason
from alte.types import Box, RegisteredFrame, Trajectory

__all__ = ["Merged", "Registered", "cache_key", "merge_frames", "merged_cloud", "prepare"]

#: Bump when the registered output of the same input and spec changes.
CACHE_VERSION = 6
_POINTS, _ARRAYS, _META = "points.f64", "arrays.npz", "meta.json"
#: The odometry's pose cache inside a registration cache folder.
POSE_DIR = "poses"


@dataclass(frozen=True, eq=False)
class Registered:
    """An input registered with one frame spec (module docstring)."""

    source: Source
    spec: FrameSettings
    points: NDArray[np.float64]
    offsets: NDArray[np.int64]
    trajectory: Trajectory
    cloud: NDArray[np.float64]
    counts: StreamCounts
    key: str = ""

    def __len__(self) -> int:
        return len(self.trajectory)

    def frame(self, i: int) -> RegisteredFrame:
        """Frame ``i`` (its points are a view of :attr:`points`)."""
        t = self.trajectory
        pts = self.points[self.offsets[i]:self.offsets[i + 1]]
        return RegisteredFrame(int(t.stamps[i]), np.asarray(pts), t.origins[i], t.positions[i],
                               t.quaternions[i])

    def frames(self) -> Iterator[RegisteredFrame]:
        """Every frame in order."""
        return (self.frame(i) for i in range(len(self)))

    def bounds(self) -> Box:
        """The box of every frame's points."""
        return Box.around(self.points)


def cache_key(source: Source, spec: FrameSettings) -> str:
    """sha256 of the input's identity, the resolved frame spec and the versions."""
    text = json.dumps({"input": source.identity, "spec": spec.key(), "cache": CACHE_VERSION,
                       "alte": __version__}, sort_keys=True)
    return hashlib.sha256(text.encode()).hexdigest()[:32]


def _collect(source: Source, spec: FrameSettings, sink: BinaryIO | None, progress: bool,
             pose_cache: Path | None) -> tuple[list[NDArray[np.float64]], NDArray[np.int64],
                                               Trajectory, NDArray[np.float64], StreamCounts]:
    """Stream the frames once: points to ``sink`` (or a list), trajectory, merged cloud."""
    counts = StreamCounts()
    merge = GridAccumulator(spec.voxel) if spec.voxel is not None else None
    parts: list[NDArray[np.float64]] = []
    sizes: list[int] = []
    poses: list[RegisteredFrame] = []
    for frame in stream_frames(source, spec, counts, merge=merge, progress=progress,
                               pose_cache=pose_cache):
        points = np.ascontiguousarray(frame.points, dtype=np.float64)
        if sink is None:
            parts.append(points)
        else:
            sink.write(points.tobytes())
        sizes.append(len(points))
        poses.append(RegisteredFrame(frame.stamp, np.empty((0, 3)), frame.origin,
                                     frame.position, frame.quaternion))
    if not sizes:
        raise RegistrationError(f"{source.path}: {empty_reason(counts.registration)}")
    offsets = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
    cloud = merge.points() if merge is not None else np.empty((0, 3))
    counts.registration.points_out = len(cloud) if merge is not None else int(offsets[-1])
    return parts, offsets, Trajectory.of(poses), cloud, counts


def _meta(source: Source, spec: FrameSettings, counts: StreamCounts) -> dict[str, object]:
    return {"input": str(source.path), "spec": spec.key(), "counts": counts.as_dict()}


def _write(target: Path, source: Source, spec: FrameSettings, progress: bool,
           pose_cache: Path | None) -> None:
    with ExitStack() as stack:
        tmp = stack.enter_context(atomic_dir(target, overwrite=False))
        tmp.mkdir(parents=True)
        sink = stack.enter_context((tmp / _POINTS).open("wb"))
        _, offsets, traj, cloud, counts = _collect(source, spec, sink, progress, pose_cache)
        sink.close()
        np.savez(tmp / _ARRAYS, offsets=offsets, stamps=traj.stamps, positions=traj.positions,
                 quaternions=traj.quaternions, origins=traj.origins, cloud=cloud)
        (tmp / _META).write_text(json.dumps(_meta(source, spec, counts), indent=1))


def _counts(folder: Path) -> StreamCounts:
    """The counts of a cache's metadata (as ``StreamCounts.as_dict`` wrote them: JSON, whose
    parser gives untyped values; the counts' constructors take them by name)."""
    raw = json.loads((folder / _META).read_text())["counts"]
    read = ReadCounts(**raw["read"])
    reg = RegistrationCounts(**raw["registration"])
    poses = PoseCounts(**raw.get("poses", {}))
    deskew = DeskewCounts(**raw.get("deskew", {}))
    return StreamCounts(read, reg, int(raw["scans"]), int(raw["selected"]), list(raw["notes"]),
                        poses, deskew)


def _load(folder: Path, source: Source, spec: FrameSettings, key: str) -> Registered:
    counts = _counts(folder)
    with np.load(folder / _ARRAYS) as arrays:
        a = {k: arrays[k] for k in arrays.files}
    total = int(a["offsets"][-1])
    points = np.memmap(folder / _POINTS, dtype=np.float64, mode="r", shape=(total, 3)) \
        if total else np.empty((0, 3))
    cloud = a["cloud"] if spec.voxel is not None else points
    traj = Trajectory(a["stamps"], a["positions"], a["quaternions"], a["origins"])
    return Registered(source, spec, points, a["offsets"], traj, cloud, counts, key)


def prepare(source: Source, spec: FrameSettings | None = None, *, cache: Path | None = None,
            progress: bool = False, pose_cache: Path | None = None) -> Registered:
    """Register ``source`` once (module docstring); ``spec`` is resolved against the input.

    Odometry keeps its poses in ``pose_cache`` (default with ``cache``: ``cache/poses``;
    :mod:`alte.pipeline.posecache`), so another frame selection of the same input and
    pose settings reads them instead of aligning the scans again.
    """
    resolved = source.resolve(spec or FrameSettings())
    key = cache_key(source, resolved)
    if pose_cache is None and cache is not None:
        pose_cache = Path(cache) / POSE_DIR
    if cache is None:
        parts, offsets, traj, cloud, counts = _collect(source, resolved, None, progress,
                                                       pose_cache)
        points = np.concatenate(parts) if parts else np.empty((0, 3))
        return Registered(source, resolved, points, offsets, traj,
                          cloud if resolved.voxel is not None else points, counts, key)
    folder = Path(cache) / key
    if not (folder / _META).is_file():
        try:
            _write(folder, source, resolved, progress, pose_cache)
        except AlteError:  # another process finished it first: read theirs
            if not (folder / _META).is_file():
                raise
    return _load(folder, source, resolved, key)



@dataclass(frozen=True, eq=False)
class Merged:
    """An input's merged registered cloud, its points' other fields (a point file's, kept
    while every point is) and the counts."""

    points: NDArray[np.float64]
    fields: Fields
    counts: StreamCounts


def merge_frames(source: Source, spec: FrameSettings | None = None, *,
                 progress: bool = False) -> Merged:
    """The input's merged registered cloud (thesis 2.1.3), streamed: with a voxel only the
    box grid is held, never the frames; without one every registered point is kept, with
    its fields."""
    resolved = source.resolve(spec or FrameSettings())
    counts = StreamCounts()
    merge = GridAccumulator(resolved.voxel) if resolved.voxel is not None else None
    frames = [f for f in stream_frames(source, resolved, counts, merge=merge,
                                       progress=progress) if merge is None]
    if counts.registration.frames_kept == 0:
        raise RegistrationError(f"{source.path}: {empty_reason(counts.registration)}")
    cloud = merge.points() if merge is not None else np.concatenate([f.points for f in frames])
    counts.registration.points_out = len(cloud)
    names = set.intersection(*(set(f.fields or {}) for f in frames)) if frames else set()
    order = [k for k in (frames[0].fields or {}) if k in names] if frames else []
    fields = {k: np.concatenate([(f.fields or {})[k] for f in frames]) for k in order}
    return Merged(cloud, fields, counts)


def merged_cloud(source: Source, spec: FrameSettings | None = None, *,
                 progress: bool = False) -> tuple[NDArray[np.float64], StreamCounts]:
    """The points and counts of :func:`merge_frames`."""
    merged = merge_frames(source, spec, progress=progress)
    return merged.points, merged.counts
