"""LiDAR odometry and pose refinement against the simulator's truth, on the eight terrains.

For each terrain the mission is registered four times through the pipeline (poses
``recorded``, ``odometry`` with each backend, point-to-plane and KISS-ICP, and
``refine``; cached like the chapters' registrations) and scored against the truth:
the trajectory error (ATE: RMSE of body positions after the rigid alignment of
:func:`align_rigid`) of each, and the merged cloud's mean distance to the true mesh.
Odometry is anchored at the recorded pose of the first scan (the terrain bags have
poses), so its cloud lies in the map frame; its ATE is nevertheless computed after
alignment, as usual for odometry.
``exp_nav_2`` is the case the thesis lost frames to: recorded poses desynchronised
by 80 ms during fast yaw swings.
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
from tqdm.auto import tqdm

from alte.errors import ParameterError
from alte.pipeline import FrameSpec, PoseSource, Registered, open_input, prepare
from alte.registration.odometry import OdometryParams
from alte.studies.experiments import CACHE_DIR
from alte.studies.tables import write_csv

__all__ = ["SOURCES", "PoseRun", "align_rigid", "ate", "odometry_row", "odometry_table",
           "write_odometry_table"]

#: The pose sources compared, in table order: column key, pose source, odometry backend.
SOURCES: tuple[tuple[str, PoseSource, str], ...] = (
    ("recorded", PoseSource.RECORDED, "plane"), ("odometry", PoseSource.ODOMETRY, "plane"),
    ("kiss", PoseSource.ODOMETRY, "kiss"), ("refine", PoseSource.REFINE, "plane"))


def align_rigid(source: np.ndarray, target: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rotation R and translation t minimising ``|target - (source R^T + t)|`` (Kabsch /
    Umeyama without scale) for matched (N, 3) point sets."""
    src = np.asarray(source, dtype=np.float64).reshape(-1, 3)
    dst = np.asarray(target, dtype=np.float64).reshape(-1, 3)
    if src.shape != dst.shape or len(src) < 3:
        raise ParameterError(f"align_rigid: need two matched sets of >= 3 points, got "
                             f"{src.shape} and {dst.shape}")
    mu_s, mu_d = src.mean(axis=0), dst.mean(axis=0)
    u, _, vt = np.linalg.svd((dst - mu_d).T @ (src - mu_s))
    sign = np.sign(np.linalg.det(u @ vt)) or 1.0
    rotation = u @ np.diag([1.0, 1.0, sign]) @ vt
    return rotation, mu_d - rotation @ mu_s


def ate(estimated: np.ndarray, truth: np.ndarray) -> float:
    """Absolute trajectory error: RMSE of positions after rigid alignment (m)."""
    rotation, shift = align_rigid(estimated, truth)
    moved = np.asarray(estimated, dtype=np.float64) @ rotation.T + shift
    return float(np.sqrt(np.mean(np.sum((moved - truth) ** 2, axis=1))))


@dataclass(frozen=True)
class PoseRun:
    """One registration of a terrain with one pose source, scored."""

    source: PoseSource
    ate_m: float
    mesh_mean_m: float
    frames: int
    frames_selected: int
    corrected: int
    above_bound: int
    seconds: float


def _score(reg: Registered, truth_stamps: np.ndarray, truth_positions: np.ndarray,
           source: PoseSource, seconds: float) -> PoseRun:
    from alte.sim import load_ground_truth, mesh_distance

    traj = reg.trajectory
    index = np.searchsorted(truth_stamps, traj.stamps)
    if np.any(index >= len(truth_stamps)) or np.any(truth_stamps[index] != traj.stamps):
        raise ParameterError(f"{reg.source.path}: registered stamps are not the scan stamps")
    scene = load_ground_truth(reg.source.path)
    poses = reg.counts.poses
    return PoseRun(source, ate(traj.positions, truth_positions[index]),
                   float(mesh_distance(np.asarray(reg.cloud), scene).mean()), len(reg),
                   reg.counts.selected, poses.corrected, poses.corrections_above_bound,
                   seconds)


def odometry_row(name: str, data_dir: str | os.PathLike[str] = "data", frames: int | None = None,
                 seed: int = 0, progress: bool = False) -> dict[str, object]:
    """One terrain's row: ATE and mesh distance per pose source (module docstring)."""
    from alte.sim import ensure_terrain, get_terrain, true_poses

    folder = ensure_terrain(name, data_dir, seed, frames, progress=progress)
    truth = true_poses(get_terrain(name), seed, frames)
    source = open_input(folder)
    row: dict[str, object] = {"terrain": name}
    for key, pose, method in SOURCES:
        start = time.perf_counter()
        spec = FrameSpec(frames=frames, poses=pose, odometry=OdometryParams(method=method))
        reg = prepare(source, spec, cache=Path(data_dir) / CACHE_DIR, progress=progress)
        done = _score(reg, truth.stamps, truth.positions, pose, time.perf_counter() - start)
        row.update({f"ate_{key}_m": done.ate_m, f"mesh_{key}_m": done.mesh_mean_m,
                    f"frames_{key}": done.frames, f"seconds_{key}": done.seconds})
        if pose is PoseSource.REFINE:
            row.update({"refine_corrected": done.corrected,
                        "refine_above_bound": done.above_bound})
    row["frames_selected"] = done.frames_selected
    steps = np.diff(truth.positions, axis=0)
    row["path_m"] = float(np.linalg.norm(steps, axis=1).sum())
    return row


def odometry_table(names: list[str] | None = None, data_dir: str | os.PathLike[str] = "data",
                   frames: int | None = None, seed: int = 0,
                   progress: bool = True) -> pd.DataFrame:
    """The table for ``names`` (default: the eight terrains), full 10 Hz missions unless
    ``frames`` asks for a reduced one."""
    from alte.sim import TERRAINS

    chosen = list(names or TERRAINS)
    unknown = sorted(set(chosen) - set(TERRAINS))
    if unknown:
        raise ParameterError(f"unknown terrain(s) {', '.join(unknown)}; "
                             f"valid: {', '.join(TERRAINS)}")
    rows = [odometry_row(n, data_dir, frames, seed, progress)
            for n in tqdm(chosen, desc="odometry", unit="terrain", disable=not progress)]
    return pd.DataFrame(rows)


def write_odometry_table(table: pd.DataFrame, out_dir: str | os.PathLike[str],
                         overwrite: bool = False) -> Path:
    """``out_dir/odometry.csv`` (the report's table writer)."""
    return write_csv(table, out_dir, "odometry", overwrite)
