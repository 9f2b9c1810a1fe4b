"""The pose benchmark: every pose source of a recording scored against reference poses.

An input is a bag (its pose topic, or a TUM file, is the reference) or a simulated
terrain (the simulator's true poses are the reference, written as a TUM file beside the
registration cache). Each pose source (``recorded``, LiDAR odometry with each backend,
``refine``) registers the scans through the pipeline, and is scored
(:mod:`alte.metrics.trajectory`): ATE and RPE against the reference poses sampled at
the same scans, and the registered cloud's median / p90 distance to the cloud registered
with the reference poses (a grid five times finer than the source clouds' voxel), twice:
as the pipeline placed it (``cloud_*``) and after the rigid alignment ATE uses
(``cloud_aligned_*``), plus,
on a terrain, the mean distance to the true mesh. ``ms_per_scan`` is the time the pose
step itself took (odometry or refinement; reading and registering are not counted), wall
and CPU (the machine may be shared: CPU time is the steadier figure).

Odometry's poses and cloud are moved so that its first scan sits at the reference pose
of that scan (the pipeline anchors odometry at the recorded pose of the first scan, or
at the first body frame when the bag has no poses), so its cloud is compared in the
reference frame and drift counts in full: one scan's error at the start (the first
alignment, to a map of a single scan) tilts the whole cloud. Its ATE, and the
``cloud_aligned_*`` distances, are taken after the rigid (Umeyama) alignment of the
trajectory instead, as evo does: the frame of a trajectory estimated without reference
is arbitrary, and comparing clouds needs some choice of it.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from alte.errors import ParameterError
from alte.lab.studies.analysis.tables import write_csv
from alte.lab.studies.experiments import CACHE_DIR
from alte.metrics.hausdorff import target_index
from alte.metrics.nearest import NearestIndex
from alte.metrics.trajectory import cloud_distance, rigid_alignment, trajectory_errors
from alte.pipeline import FrameSettings, PoseSource, Registered, Source, open_input, prepare
from alte.progress import bar as progress_bar
from alte.registration.odometry import OdometrySettings

__all__ = ["COLUMNS", "REAL_SEQUENCES", "SOURCES", "BenchInput", "bench_input", "odometry_table",
           "pose_benchmark", "realdata_table", "write_odometry_table"]

#: Pose sources in table order: name -> (pose source, odometry backend or None).
SOURCES: dict[str, tuple[PoseSource, str | None]] = {
    "recorded": (PoseSource.RECORDED, None), "kiss": (PoseSource.ODOMETRY, "kiss"),
    "plane": (PoseSource.ODOMETRY, "plane"), "refine": (PoseSource.REFINE, None)}
#: Voxel (m) of a bag's clouds when neither the input nor the caller sets one.
BAG_VOXEL = 0.05
#: The table's columns (units in the names).
COLUMNS = ("input", "source", "settings", "frames", "path_m", "ate_m", "rpe_trans_pct",
           "rpe_rot_deg_m", "cloud_median_m", "cloud_p90_m", "cloud_aligned_median_m",
           "cloud_aligned_p90_m", "mesh_mean_m", "ms_per_scan",
           "cpu_ms_per_scan", "corrected", "kept")


@dataclass(frozen=True)
class BenchInput:
    """One recording to score: the input, its reference poses (TUM file, or None for the
    bag's own pose topic), the clouds' voxel and the scans read (None: all)."""

    name: str
    source: Source
    reference: Path | None
    voxel: float
    frames: int | None = None


def _terrain_input(name: str, data_dir: Path, frames: int | None, seed: int) -> BenchInput:
    from alte.io.poses.tum import write_tum
    from alte.sim import ensure_terrain, get_terrain, true_poses

    folder = ensure_terrain(name, data_dir, seed, frames)
    source = open_input(folder)
    truth = true_poses(get_terrain(name), seed, frames)
    tum = data_dir / CACHE_DIR / f"truth-{name}-{seed}-{frames or 'all'}.tum"
    if not tum.is_file():
        write_tum(tum, truth.stamps, truth.positions, truth.quaternions,
                  header=f"true body poses of {name} (seed {seed}); t x y z qx qy qz qw")
    return BenchInput(name, source, tum, float(source.voxel or BAG_VOXEL), frames)


def _name(path: Path, name: str) -> str:
    """A bag's name in the table: its folder's, or its parent's when the folder is only
    called ``bag`` (``balm_seq/bag``, a terrain folder's ``bag``)."""
    path = path.resolve()
    return path.parent.name if path.name == "bag" else (name or path.name)


def bench_input(what: str | os.PathLike[str], *, reference: str | os.PathLike[str] | None = None,
                voxel: float | None = None, frames: int | None = None,
                data_dir: str | os.PathLike[str] = "data", seed: int = 0) -> BenchInput:
    """A terrain name (simulated when absent, true poses as reference) or a bag / terrain
    folder (``reference``: a TUM file; None: the bag's pose topic)."""
    from alte.sim import TERRAINS

    if str(what) in TERRAINS:
        if reference is not None:
            raise ParameterError(f"reference: {what} is a simulated terrain; its true "
                                 "poses are the reference", setting="odometry study.reference")
        made = _terrain_input(str(what), Path(data_dir), frames, seed)
        return made if voxel is None else replace(made, voxel=voxel)
    if not Path(what).exists():
        raise ParameterError(f"{what}: neither a simulated terrain ({', '.join(TERRAINS)}) "
                             "nor a bag or terrain folder")
    source = open_input(Path(what))
    if reference is not None and not Path(reference).is_file():
        raise ParameterError(f"reference={reference}: no such TUM file",
                             setting="odometry study.reference")
    return BenchInput(_name(Path(what), source.name), source,
                      None if reference is None else Path(reference),
                      voxel or source.voxel or BAG_VOXEL, frames)


def _spec(item: BenchInput, poses: PoseSource, odometry: OdometrySettings) -> FrameSettings:
    return FrameSettings(frames=item.frames, voxel=item.voxel, poses=poses, odometry=odometry)


def _reference_spec(item: BenchInput) -> FrameSettings:
    return FrameSettings(frames=item.frames, voxel=item.voxel / 5, poses=PoseSource.RECORDED,
                     pose_file=item.reference)


def _anchored(reg: Registered, reference: Registered, mine: NDArray[np.intp],
              theirs: NDArray[np.intp],
              ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Odometry's positions, quaternions and cloud moved so that its first matched pose is
    the reference's (module docstring)."""
    from scipy.spatial.transform import Rotation

    from alte.registration.odometry import pose_matrix

    est, ref = reg.trajectory, reference.trajectory
    first = pose_matrix(ref.positions[theirs[0]], ref.quaternions[theirs[0]]) @ np.linalg.inv(
        pose_matrix(est.positions[mine[0]], est.quaternions[mine[0]]))
    turn, shift = first[:3, :3], first[:3, 3]
    quats = (Rotation.from_matrix(turn) * Rotation.from_quat(est.quaternions[mine])).as_quat()
    return (est.positions[mine] @ turn.T + shift, quats,
            np.asarray(reg.cloud) @ turn.T + shift)


def _matched(reg: Registered, reference: Registered,
             ) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
    """Indices of the scans both registrations kept, in each."""
    common, mine, theirs = np.intersect1d(reg.trajectory.stamps, reference.trajectory.stamps,
                                          return_indices=True)
    if len(common) < 3:
        raise ParameterError(f"{reg.source.path}: only {len(common)} scans have both an "
                             "estimated and a reference pose")
    return mine, theirs


def _score(item: BenchInput, key: str, reg: Registered, reference: Registered,
           near: NearestIndex, *, odometry: OdometrySettings) -> dict[str, object]:
    mine, theirs = _matched(reg, reference)
    est, ref = reg.trajectory, reference.trajectory
    if reg.spec.poses is PoseSource.ODOMETRY:
        positions, quaternions, points = _anchored(reg, reference, mine, theirs)
    else:
        positions, quaternions = est.positions[mine], est.quaternions[mine]
        points = np.asarray(reg.cloud)
    errors = trajectory_errors(est.stamps[mine], positions, quaternions,
                               ref.positions[theirs], ref.quaternions[theirs])
    cloud = cloud_distance(points, near)
    align = rigid_alignment(positions, ref.positions[theirs])
    aligned = cloud_distance(points @ align[:3, :3].T + align[:3, 3], near)
    poses = reg.counts.poses
    path = float(np.linalg.norm(np.diff(ref.positions[theirs], axis=0), axis=1).sum())
    return {"input": item.name, "source": key, "settings": _settings(key, odometry),
            "frames": len(reg), "path_m": path, "ate_m": errors.ate_m,
            "rpe_trans_pct": errors.rpe_trans_pct, "rpe_rot_deg_m": errors.rpe_rot_deg_m,
            "cloud_median_m": cloud.median_m, "cloud_p90_m": cloud.p90_m,
            "cloud_aligned_median_m": aligned.median_m, "cloud_aligned_p90_m": aligned.p90_m,
            "mesh_mean_m": _mesh_mean(item, points),
            "ms_per_scan": 1e3 * poses.seconds / max(poses.frames, 1),
            "cpu_ms_per_scan": 1e3 * poses.cpu_seconds / max(poses.frames, 1),
            "corrected": poses.corrected if key == "refine" else 0,
            "kept": poses.frames - poses.corrected if key == "refine" else 0}


def _settings(key: str, odometry: OdometrySettings) -> str:
    """The settings a source ran with, as ``key=value`` text (those that differ from the
    defaults), or ``-`` for recorded poses."""
    if key == "recorded":
        return "-"
    default = OdometrySettings(method=odometry.method).as_dict()
    changed = {k: v for k, v in odometry.as_dict().items() if v != default[k]}
    return " ".join(f"{k}={v}" for k, v in changed.items()) or "defaults"


def _mesh_mean(item: BenchInput, points: NDArray[np.float64]) -> float:
    if item.source.ground_truth() is None:
        return float("nan")
    from alte.sim import load_ground_truth, mesh_distance

    scene = load_ground_truth(item.source.path)
    return float(mesh_distance(points, scene).mean())


def pose_benchmark(item: BenchInput, sources: Sequence[str] = tuple(SOURCES), *,
                   settings: Mapping[str, Mapping[str, object]] | None = None,
                   cache: Path | None = None, progress: bool = False) -> pd.DataFrame:
    """One row per pose source of ``item`` (module docstring); ``settings`` maps a
    backend (``kiss``, ``plane``, ``refine``) to :class:`OdometrySettings` overrides."""
    unknown = sorted(set(sources) - set(SOURCES))
    if unknown:
        raise ParameterError(f"unknown pose source(s) {', '.join(unknown)}; "
                             f"valid: {', '.join(SOURCES)}")
    settings = settings or {}
    reference = prepare(item.source, _reference_spec(item), cache=cache, progress=progress)
    near = target_index(reference.cloud)  # every source's cloud is measured against it
    rows = []
    for key in sources:
        poses, method = SOURCES[key]
        odometry = OdometrySettings.parse({"method": method or "kiss", **settings.get(key, {})})
        reg = prepare(item.source, _spec(item, poses, odometry), cache=cache,
                      progress=progress)
        rows.append(_score(item, key, reg, reference, near, odometry=odometry))
    return pd.DataFrame(rows, columns=list(COLUMNS))


def odometry_table(inputs: Sequence[str | os.PathLike[str]] | None = None, *,
                   reference: str | os.PathLike[str] | None = None,
                   data_dir: str | os.PathLike[str] = "data", frames: int | None = None,
                   seed: int = 0, voxel: float | None = None,
                   sources: Sequence[str] = tuple(SOURCES),
                   settings: Mapping[str, Mapping[str, object]] | None = None,
                   progress: bool = True) -> pd.DataFrame:
    """The benchmark over ``inputs`` (terrain names or bag / terrain folders; default: the
    eight terrains), registrations cached under ``data_dir``."""
    from alte.sim import TERRAINS

    chosen = [str(v) for v in inputs] if inputs else list(TERRAINS)
    cache = Path(data_dir) / CACHE_DIR
    tables = []
    for what in progress_bar(chosen, desc="pose benchmark", unit="input", disable=not progress):
        item = bench_input(what, reference=reference, voxel=voxel, frames=frames,
                           data_dir=data_dir, seed=seed)
        tables.append(pose_benchmark(item, sources, settings=settings, cache=cache,
                                     progress=progress))
    return pd.concat(tables, ignore_index=True)


#: The real sequences of the benchmark (folders under the real-data folder, each with a
#: ``bag`` holding its reference poses): two non-overlapping stretches of one recording.
REAL_SEQUENCES = ("balm_seq", "balm_seq2")


def realdata_table(root: Path | None, terrains: Sequence[str] = (), *,
                   sequences: Sequence[str] = REAL_SEQUENCES,
                   sources: Sequence[str] = tuple(SOURCES),
                   data_dir: str | os.PathLike[str] = "data",
                   progress: bool = False) -> pd.DataFrame:
    """The benchmark on the real ``sequences`` present under ``root`` (their pose topic as
    the reference), then on ``terrains``; an empty table when ``root`` is None (no real
    data)."""
    if root is None:
        return pd.DataFrame(columns=list(COLUMNS))
    bags = [Path(root) / name / "bag" for name in sequences]
    inputs = [str(b) for b in bags if b.exists()] + list(terrains)
    if not inputs:
        return pd.DataFrame(columns=list(COLUMNS))
    return odometry_table(inputs, data_dir=data_dir, sources=sources, progress=progress)


def write_odometry_table(table: pd.DataFrame, out_dir: str | os.PathLike[str],
                         overwrite: bool = False, name: str = "odometry") -> Path:
    """``out_dir/NAME.csv`` (the report's table writer)."""
    return write_csv(table, out_dir, name, overwrite)
