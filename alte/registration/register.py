"""Point cloud registration (thesis 2.1.2-2.1.3, 2.2.4, ch. 4): sensor frames -> one inertial cloud.

Every frame is transformed with eq. 2.2, cropped to the control volume (2.2.4),
grid-average down-sampled (2.1.3 step 2) and merged into the cloud with a box-grid
filter (2.1.3 step 3). Frames taken during fast manoeuvres are dropped first (ch. 4).

The thesis merges pairwise, MATLAB ``pcmerge``-style: the accumulated cloud and the
next scan are concatenated and every box of the grid is replaced by the mean of the
points in it (:func:`box_grid_merge`). That costs O(cloud) per frame, O(F^2) in
total, and weighs a cell's old representative like one new point. :class:`GridAccumulator`
keeps per-cell sums and point counts instead, so merging a frame costs O(frame) and
the result is the grid average of *all* raw points that fell in each cell, whatever
the frame order. Grids are anchored at the inertial origin (MATLAB anchors them at
the cloud's lower limits), so the output is deterministic and order-independent.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from alte.errors import ParameterError, RegistrationError
from alte.progress import bar as progress_bar
from alte.registration.grid import (
    GridAccumulator,
    check_voxel,
    grid_average,
    grid_average_with_counts,
)
from alte.registration.transform import register_with_origin
from alte.types import Counts, Frame, Mount, finite_rows, rows_all

__all__ = [
    "ManoeuvreFilter",
    "Registration",
    "RegistrationCounts",
    "check_options",
    "crop",
    "crop_mask",
    "empty_reason",
    "register",
    "register_frames",
]


def crop_mask(points: NDArray[np.float64], box: tuple[float, ...] | NDArray[np.float64],
              ) -> NDArray[np.bool_]:
    """Points inside ``box = (xmin, ymin, zmin, xmax, ymax, zmax)``, bounds inclusive."""
    arr = np.asarray(box, dtype=np.float64).reshape(-1)
    if arr.shape != (6,) or not np.isfinite(arr).all() or np.any(arr[:3] > arr[3:]):
        raise ParameterError(
            f"crop box {np.asarray(box).tolist()} must be 6 finite numbers "
            "xmin,ymin,zmin,xmax,ymax,zmax with min <= max"
        )
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    return rows_all((pts >= arr[:3]) & (pts <= arr[3:]))


def crop(points: NDArray[np.float64], box: tuple[float, ...] | NDArray[np.float64],
         ) -> NDArray[np.float64]:
    """Keep only the points inside the control volume (thesis 2.2.4)."""
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    kept: NDArray[np.float64] = pts[crop_mask(pts, box)]
    return kept


def _check_limit(name: str, value: float | None) -> float | None:
    if value is None:
        return None
    limit = float(value)
    if not np.isfinite(limit) or limit <= 0:
        raise ParameterError(f"{name}={value!r} must be a positive finite number (or None)")
    return limit


class ManoeuvreFilter:
    """Drop frames taken during fast manoeuvres (thesis ch. 4), counting why.

    A frame whose body rate exceeds ``max_rate_rad_s`` or whose pose is more than
    ``max_offset_s`` away from the scan stamp is dropped; a frame failing both is
    counted under ``rate``.
    """

    def __init__(self, max_rate_rad_s: float | None = None, max_offset_s: float | None = None):
        self.max_rate = _check_limit("max_rate_rad_s", max_rate_rad_s)
        self.max_offset = _check_limit("max_offset_s", max_offset_s)
        self.dropped: dict[str, int] = {"rate": 0, "offset": 0}

    def reason(self, frame: Frame) -> str | None:
        """None when the frame passes, else why it is dropped (``rate``/``offset``), counted."""
        why = None
        if self.max_rate is not None and not abs(frame.angular_rate) <= self.max_rate:
            why = "rate"
        elif self.max_offset is not None and not abs(frame.pose_offset_s) <= self.max_offset:
            why = "offset"
        if why is not None:
            self.dropped[why] += 1
        return why

    def keep(self, frame: Frame) -> bool:
        """True when the frame passes the filter."""
        return self.reason(frame) is None


@dataclass
class RegistrationCounts(Counts):
    """Frames and points in, dropped by reason, and out; updated as frames stream through."""

    frames_in: int = 0
    frames_kept: int = 0
    frames_dropped_rate: int = 0
    frames_dropped_offset: int = 0
    frames_dropped_empty: int = 0
    points_in: int = 0
    points_dropped_nonfinite: int = 0
    points_dropped_crop: int = 0
    points_registered: int = 0
    points_out: int = 0

    def drop_frame(self, reason: str) -> None:
        """Count a frame dropped for ``reason`` (rate, offset or empty)."""
        name = f"frames_dropped_{reason}"
        setattr(self, name, getattr(self, name) + 1)


def _frame_points(
    frame: Frame, mount: Mount, box: NDArray[np.float64] | None, counts: RegistrationCounts
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Registered, finite, cropped points of one frame and the sensor origin (one pose)."""
    raw = np.asarray(frame.points, dtype=np.float64)
    if raw.ndim != 2 or raw.shape[1] != 3:
        raise RegistrationError(f"frame at stamp {frame.stamp}: points have shape {raw.shape}")
    counts.points_in += len(raw)
    pts, origin = register_with_origin(frame, mount)
    finite = finite_rows(pts)
    if finite is not None:
        counts.points_dropped_nonfinite += len(pts) - int(finite.sum())
        pts = pts[finite]
    if box is not None:
        inside = crop_mask(pts, box)
        counts.points_dropped_crop += len(pts) - int(inside.sum())
        pts = pts[inside]
    return pts, origin


def _iterate(
    frames: Iterable[Frame],
    mount: Mount,
    *,
    counts: RegistrationCounts,
    voxel: float | None,
    crop_box: tuple[float, ...] | None,
    gate: ManoeuvreFilter,
    merge: GridAccumulator | None,
    progress: bool,
) -> Iterator[tuple[Frame, NDArray[np.float64], NDArray[np.float64]]]:
    box = None if crop_box is None else np.asarray(crop_box, dtype=np.float64)
    for frame in progress_bar(frames, desc="register", unit="frame", disable=not progress):
        counts.frames_in += 1
        reason = gate.reason(frame)
        if reason is not None:
            counts.drop_frame(reason)
            continue
        pts, origin = _frame_points(frame, mount, box, counts)
        if len(pts) == 0:
            counts.drop_frame("empty")
            continue
        pts = _merge_and_average(pts, voxel, merge)
        counts.frames_kept += 1
        counts.points_registered += len(pts)
        yield frame, pts, origin


def _merge_and_average(pts: NDArray[np.float64], voxel: float | None,
                       merge: GridAccumulator | None) -> NDArray[np.float64]:
    """The frame's points added to ``merge`` and grid-averaged at ``voxel``; on one grid
    (the pipeline's case) the points are grouped once for both, the same values."""
    if merge is not None and voxel is not None and merge.voxel == voxel:
        cells = grid_average_with_counts(pts, voxel)
        merge.add_cells(cells)
        averaged: NDArray[np.float64] = cells[1] / cells[2][:, None]
        return averaged
    if merge is not None:
        merge.add(pts)
    return pts if voxel is None else grid_average(pts, voxel)


def check_options(
    voxel: float | None = None,
    crop_box: tuple[float, ...] | None = None,
    max_rate: float | None = None,
    max_offset: float | None = None,
) -> ManoeuvreFilter:
    """Validate registration options before any frame is read; returns the frame filter."""
    if voxel is not None:
        check_voxel(voxel)
    if crop_box is not None:
        crop_mask(np.empty((0, 3)), crop_box)
    return ManoeuvreFilter(max_rate, max_offset)


def register_frames(
    frames: Iterable[Frame],
    mount: Mount,
    *,
    voxel: float | None = None,
    crop_box: tuple[float, ...] | None = None,
    max_rate: float | None = None,
    max_offset: float | None = None,
    progress: bool = False,
    counts: RegistrationCounts | None = None,
    merge: GridAccumulator | None = None,
) -> Iterator[tuple[Frame, NDArray[np.float64], NDArray[np.float64]]]:
    """Yield ``(frame, inertial points, sensor origin)`` per kept frame, for incremental mappers.

    Points are registered (eq. 2.2), stripped of NaN/inf, cropped to ``crop_box``
    and grid-averaged with ``voxel`` (when given). Frames dropped by the manoeuvre
    filter or left without points are skipped; pass a :class:`RegistrationCounts` as
    ``counts`` to get the tally (updated as frames stream through). ``merge`` receives
    each kept frame's points before down-sampling (the box-grid merge of the cloud).
    """
    gate = check_options(voxel, crop_box, max_rate, max_offset)
    tally = RegistrationCounts() if counts is None else counts
    return _iterate(
        frames, mount, counts=tally, voxel=voxel, crop_box=crop_box, gate=gate, merge=merge,
        progress=progress)


@dataclass(frozen=True)
class Registration:
    """A registered inertial cloud and what went into it.

    ``points`` (N, 3) the merged cloud, ``origins`` (F, 3) the sensor origins and
    ``stamps`` (F,) the stamps of the kept frames, ``frame_points`` (F,) how many
    registered (down-sampled, cropped) points each kept frame contributed, and
    ``counts`` frames/points in, dropped by reason, and out.
    """

    points: NDArray[np.float64]
    origins: NDArray[np.float64]
    frame_points: NDArray[np.int64]
    stamps: NDArray[np.int64]
    counts: RegistrationCounts


def register(
    frames: Iterable[Frame],
    mount: Mount,
    *,
    voxel: float | None = None,
    crop_box: tuple[float, ...] | None = None,
    max_rate: float | None = None,
    max_offset: float | None = None,
    progress: bool = False,
) -> Registration:
    """Register frames into one inertial cloud (thesis 2.1.3).

    With ``voxel`` every frame is grid-averaged and box-grid merged into the cloud
    through a :class:`GridAccumulator` (cell means weighted by raw point counts);
    without it the registered points are concatenated.
    """
    counts = RegistrationCounts()
    merged = GridAccumulator(voxel) if voxel is not None else None
    parts: list[NDArray[np.float64]] = []
    origins, stamps, sizes = [], [], []
    stream = register_frames(
        frames, mount, voxel=None, crop_box=crop_box, max_rate=max_rate,
        max_offset=max_offset, progress=progress, counts=counts,
    )
    for frame, pts, origin in stream:
        if merged is None:
            parts.append(pts)
            sizes.append(len(pts))
        else:
            sizes.append(merged.add(pts))
        origins.append(origin)
        stamps.append(frame.stamp)
    if not origins:
        raise RegistrationError(empty_reason(counts))
    points = np.vstack(parts) if merged is None else merged.points()
    counts.points_registered = int(sum(sizes))
    counts.points_out = len(points)
    return Registration(
        points, np.asarray(origins), np.asarray(sizes, np.int64),
        np.asarray(stamps, np.int64), counts,
    )


def empty_reason(counts: RegistrationCounts) -> str:
    """Explain why no frame survived registration."""
    if counts.frames_in == 0:
        return "no frames to register: the input held no frames"
    dropped = ", ".join(
        f"{n} {why}" for why, n in (("rate", counts.frames_dropped_rate),
                                    ("offset", counts.frames_dropped_offset),
                                    ("empty", counts.frames_dropped_empty)) if n)
    return f"no frame left to register: all {counts.frames_in} frames dropped ({dropped})"
