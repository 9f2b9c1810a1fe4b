"""The pipeline's odometry step: scans posed by LiDAR (or LiDAR-inertial) odometry.

Odometry aligns consecutive scans, so it reads every scan of the bag even when
``FrameSettings.frames`` keeps fewer (:attr:`alte.io.bags.bag.FrameStream.read_all`); only the
scans the selection keeps go on, posed as in a run over all of them.
"""

from __future__ import annotations

import itertools
from collections.abc import Iterator
from dataclasses import replace
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from alte.errors import PoseError
from alte.io.bags.bag import FrameStream
from alte.io.bags.imu import ImuSamples, imu_topic, read_imu
from alte.pipeline.posecache import PosedScans, pose_key, read_poses, record_poses
from alte.pipeline.spec import FrameSettings
from alte.registration.odometry import (
    OdometrySettings,
    PoseCounts,
    odometry_frames,
    odometry_label,
    resolve_method,
)
from alte.types import Frame

__all__ = ["PoseCache", "odometry_poses"]

#: Where odometry keeps its posed scans: the cache folder and the input's identity.
PoseCache = tuple[Path, str]


def _start(probe: FrameStream, stamp: int,
           ) -> tuple[NDArray[np.float64], NDArray[np.float64]] | None:
    """The recorded pose at the first scan, or None (no track, or one on another clock)."""
    if probe.track is None:
        return None
    try:
        at = probe.track.interpolate([stamp], probe.options.max_gap_s)
    except PoseError:  # stamps in another unit: odometry does without the anchor
        return None
    return (at.positions[0], at.quaternions[0]) if at.valid[0] else None


def _imu(stream: FrameStream, params: OdometrySettings) -> ImuSamples | None:
    """The bag's IMU samples when LiDAR-inertial odometry will run (``auto`` with an IMU
    topic, or ``lio``), else None."""
    if params.method not in ("auto", "lio"):
        return None
    topic = imu_topic(stream.path, params.imu_topic)
    if topic is None:
        return None
    return read_imu(stream.path, topic)


def odometry_poses(stream: FrameStream, probe: FrameStream, spec: FrameSettings,
                   counts: PoseCounts, cache: PoseCache | None = None) -> Iterator[Frame]:
    """The selected scans of ``stream`` posed by odometry (LiDAR-inertial when the bag has
    an IMU and the method is ``auto`` or ``lio``), anchored at the recorded pose of the
    first scan when ``probe`` (the stream with the pose topic) has one. With ``cache``
    (the cache folder and the input's identity) every posed scan is kept there and a run
    with the same key reads them back (:mod:`alte.pipeline.posecache`)."""
    chosen: set[int] = set()
    frames = _tagged(stream, chosen)
    if not spec.deskew:  # --no-deskew: the odometry aligns, and the map keeps, scans as taken
        frames = (replace(frame, times=None) for frame in frames)
    first = next(frames, None)
    if first is None:
        return
    start = _start(probe, first.stamp)
    anchor = f"the recorded pose of the first scan ({probe.pose_topic})" if start is not None \
        else "the first scan's body frame"
    imu = _imu(stream, spec.odometry)
    params = resolve_method(spec.odometry, imu is not None)
    kind = "LiDAR-inertial odometry" if imu is not None else "LiDAR odometry"
    with_imu = f", IMU {imu.frame_id} at {imu.rate_hz:.0f} Hz" if imu is not None else ""
    stream.notes.append(f"poses from {kind} ({odometry_label(params)}{with_imu}), "
                        f"anchored at {anchor}")
    scans = itertools.chain([first], frames)
    folder = None if cache is None else cache[0] / pose_key(cache[1], spec, params)
    kept = None if folder is None else read_poses(folder)
    if kept is not None:
        yield from _cached(scans, kept, chosen, counts, stream.notes)
        return
    posed = odometry_frames(scans, stream.mount, counts=counts, params=params, start=start,
                            imu=imu)
    if folder is not None:
        posed = record_poses(folder, posed, counts)
    yield from (frame for frame in posed if frame.stamp in chosen)


def _cached(scans: Iterator[Frame], kept: PosedScans, chosen: set[int], counts: PoseCounts,
            notes: list[str]) -> Iterator[Frame]:
    """The chosen ``scans`` posed as the cached run ``kept`` posed them; every scan is
    still read (the stream's counts stay those of a run that aligns them)."""
    for name, value in kept.counts.as_dict().items():
        setattr(counts, name, value)
    notes.append(f"odometry poses of all {len(kept.stamps)} scans read from the pose cache "
                 f"(aligned once in {kept.counts.seconds:.1f} s)")
    for frame in scans:
        if frame.stamp not in chosen:
            continue
        posed = kept.posed(frame)
        if posed is None:
            raise PoseError(f"pose cache: no posed scan at stamp {frame.stamp}; delete the "
                            "cache folder (DATA_DIR/.cache/poses) to align the scans again")
        yield posed


def _tagged(stream: FrameStream, chosen: set[int]) -> Iterator[Frame]:
    """The scans ``stream`` reads; the stamps of those its selection keeps (by index on the
    cloud topic: all unless it reads every scan) go to ``chosen``."""
    for frame in stream:
        index = stream.counts.scans_read + stream.counts.scans_skipped - 1
        if not stream.read_all or index in (stream.selection or ()):
            chosen.add(frame.stamp)
        yield frame
