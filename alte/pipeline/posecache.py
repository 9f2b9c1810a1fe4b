"""Odometry's posed scans kept on disk, so that one input is aligned once per settings.

LiDAR(-inertial) odometry reads and aligns every scan of a bag whatever the frame
selection keeps (:mod:`alte.pipeline.posing`), and it is the costly step of a posed
run: tens of seconds per simulated mission, where reading the bag takes one or two.
Studies pose the same mission many times (a sweep's 20 evenly spaced scans, the
sensor study's whole mission), so with a cache folder every scan odometry posed is
written to ``DIR/<key>/`` (its pose, the points as the odometry handed them on, the
pose counts) and a later run with the same key reads them back instead of aligning
again. The key is the input's identity (its files' sizes and times), what decides the
odometry (the resolved settings, mount, topics, pose file, deskew) and the code: the
version below and a hash of the odometry's own source files, so a changed algorithm
never reads poses an older one made.
"""

from __future__ import annotations

import functools
import hashlib
import json
from collections.abc import Iterable, Iterator
from contextlib import ExitStack
from dataclasses import dataclass, replace
from pathlib import Path
from typing import cast

import numpy as np
from numpy.typing import NDArray

from alte import __version__
from alte.errors import AlteError
from alte.fsutil import atomic_dir
from alte.pipeline.spec import FrameSettings
from alte.registration.odometry import OdometrySettings
from alte.registration.settings import PoseCounts
from alte.types import Frame

__all__ = ["CACHE_VERSION", "PosedScans", "code_hash", "pose_key", "read_poses", "record_poses"]

#: Bump when the posed scans of the same input and settings change other than by code
#: (the hash of the odometry's sources covers the code itself).
CACHE_VERSION = 1
_POINTS, _ARRAYS, _META = "points.bin", "arrays.npz", "meta.json"
#: The sources whose code decides the odometry's output (hashed into every key).
_SOURCES = ("registration", "io/bags/imu.py", "io/bags/bag.py", "pipeline/posing.py")


@functools.cache
def code_hash() -> str:
    """sha256 of the odometry's source files (:data:`_SOURCES`), read once per process."""
    root = Path(__file__).resolve().parent.parent
    digest = hashlib.sha256()
    for name in _SOURCES:
        where = root / name
        for path in sorted(where.rglob("*.py")) if where.is_dir() else [where]:
            digest.update(path.relative_to(root).as_posix().encode())
            digest.update(path.read_bytes())
    return digest.hexdigest()


def pose_key(identity: str, spec: FrameSettings, params: OdometrySettings) -> str:
    """The cache key of an input's odometry: ``identity`` (:attr:`Source.identity`), the
    spec's fields that decide the poses (not the selection, crop or voxel) and the
    resolved odometry ``params``."""
    whole = spec.key()
    text = json.dumps({"input": identity, "odometry": params.as_dict(),
                       **{k: whole[k] for k in ("mount", "cloud_topic", "pose_topic",
                                                "deskew", "pose_file")},
                       "cache": CACHE_VERSION, "alte": __version__, "code": code_hash()},
                      sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()[:32]


@dataclass(frozen=True, eq=False)
class PosedScans:
    """Every scan of a cached odometry run: stamps, poses and the points it passed on."""

    stamps: NDArray[np.int64]
    positions: NDArray[np.float64]
    quaternions: NDArray[np.float64]
    rates: NDArray[np.float64]
    timed: NDArray[np.bool_]
    offsets: NDArray[np.int64]
    points: NDArray[np.float32] | NDArray[np.float64]
    counts: PoseCounts

    @functools.cached_property
    def index(self) -> dict[int, int]:
        """Stamp -> row."""
        return {int(s): i for i, s in enumerate(self.stamps)}

    def posed(self, frame: Frame) -> Frame | None:
        """``frame`` (as read from the bag) as the odometry passed it on; None when the
        cached run has no scan at its stamp."""
        i = self.index.get(frame.stamp)
        if i is None:
            return None
        # the dtype the odometry passed on (the bag's, as Frame.points are typed loosely)
        rows = slice(self.offsets[i], self.offsets[i + 1])
        pts = cast("NDArray[np.float64]", np.array(self.points[rows]))
        return replace(frame, points=pts, position=self.positions[i].copy(),
                       quaternion=self.quaternions[i].copy(), pose_offset_s=0.0,
                       angular_rate=float(self.rates[i]),
                       times=frame.times if self.timed[i] else None)


def read_poses(folder: Path) -> PosedScans | None:
    """The cached run in ``folder``, or None when there is none (or an unreadable one)."""
    try:
        meta = json.loads((folder / _META).read_text())
        with np.load(folder / _ARRAYS) as arrays:
            a = {k: arrays[k] for k in arrays.files}
    except (OSError, ValueError):
        return None
    total = int(a["offsets"][-1])
    points = np.memmap(folder / _POINTS, dtype=np.dtype(meta["dtype"]), mode="r",
                       shape=(total, 3)) if total else np.empty((0, 3))
    return PosedScans(a["stamps"], a["positions"], a["quaternions"], a["rates"], a["timed"],
                      a["offsets"], points, PoseCounts(**meta["counts"]))


def record_poses(folder: Path, posed: Iterable[Frame], counts: PoseCounts) -> Iterator[Frame]:
    """``posed`` passed through unchanged, every frame also written to ``folder``; the
    folder appears (atomically) only when ``posed`` ran to its end, with ``counts`` as
    they stand then. Another process that finished the same folder first wins."""
    with ExitStack() as stack:
        try:
            tmp = stack.enter_context(atomic_dir(folder, overwrite=False))
        except AlteError:  # finished meanwhile by another process
            yield from posed
            return
        tmp.mkdir(parents=True)
        sink = stack.enter_context((tmp / _POINTS).open("wb"))
        rows: list[tuple[int, NDArray[np.float64], NDArray[np.float64], float, bool, int]] = []
        dtype = "float64"
        for frame in posed:
            points = np.ascontiguousarray(frame.points)
            dtype = points.dtype.str
            sink.write(points.tobytes())
            rows.append((frame.stamp, np.asarray(frame.position), np.asarray(frame.quaternion),
                         frame.angular_rate, frame.times is not None, len(points)))
            yield frame
        sink.close()
        _finish(tmp, rows, dtype, counts)


def _finish(tmp: Path, rows: list[tuple[int, NDArray[np.float64], NDArray[np.float64], float,
                                        bool, int]], dtype: str, counts: PoseCounts) -> None:
    sizes = [r[5] for r in rows]
    np.savez(tmp / _ARRAYS, stamps=np.array([r[0] for r in rows], dtype=np.int64),
             positions=np.array([r[1] for r in rows], dtype=np.float64).reshape(-1, 3),
             quaternions=np.array([r[2] for r in rows], dtype=np.float64).reshape(-1, 4),
             rates=np.array([r[3] for r in rows], dtype=np.float64),
             timed=np.array([r[4] for r in rows], dtype=bool),
             offsets=np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64))
    (tmp / _META).write_text(json.dumps({"dtype": dtype, "counts": counts.as_dict()},
                                        default=str))
