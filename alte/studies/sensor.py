"""The realistic UAV sensor against the thesis' instantaneous scan, per terrain.

For each UAV mission (or any terrain) the ``uav`` sensor profile's bag is registered
with recorded poses as taken, recorded poses + deskew, LiDAR-only odometry (KISS-ICP) and
LiDAR-inertial odometry (:mod:`alte.registration.lio`, the bag's IMU), beside the thesis
profile's bag with recorded poses (the chapters' reference), and scored
against the simulator's truth: ATE and RPE (translation, % of 1 m segments) as evo reports
them (:mod:`alte.metrics.trajectory`) and the merged cloud's mean distance to the true
mesh, with the time per scan.
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from alte.metrics.trajectory import trajectory_errors
from alte.pipeline import FrameSpec, PoseSource, open_input, prepare
from alte.registration.odometry import odometry_params

__all__ = ["RUNS", "sensor_row", "sensor_table"]

#: Column key -> (profile, pose source, deskew, odometry backend).
RUNS: dict[str, tuple[str, PoseSource, bool, str]] = {
    "thesis": ("thesis", PoseSource.RECORDED, True, "auto"),
    "recorded": ("uav", PoseSource.RECORDED, False, "auto"),
    "deskew": ("uav", PoseSource.RECORDED, True, "auto"),
    "lidar": ("uav", PoseSource.ODOMETRY, True, "kiss"),
    "lio": ("uav", PoseSource.ODOMETRY, True, "lio"),
}


@dataclass(frozen=True)
class _Score:
    ate_m: float
    rpe_pct: float
    mesh_m: float
    ms_per_scan: float


def _score(folder: Path, name: str, run: tuple[PoseSource, bool, str], seed: int,
           cache: Path | None) -> _Score:
    from alte.sim import get_terrain, load_ground_truth, mesh_distance, true_poses

    pose, deskew, method = run
    spec = FrameSpec(poses=pose, deskew=deskew, odometry=odometry_params(method))
    start = time.perf_counter()
    reg = prepare(open_input(folder), spec, cache=cache)
    seconds = time.perf_counter() - start
    if pose is PoseSource.ODOMETRY:  # the pose step alone, as `alte register` reports it
        seconds = reg.counts.poses.seconds
    truth = true_poses(get_terrain(name), seed)
    traj = reg.trajectory
    index = np.searchsorted(truth.stamps, traj.stamps)
    tp, tq = truth.positions[index], truth.quaternions[index]
    mesh = float(mesh_distance(np.asarray(reg.cloud), load_ground_truth(folder)).mean())
    errors = trajectory_errors(traj.stamps, traj.positions, traj.quaternions, tp, tq)
    return _Score(errors.ate_m, errors.rpe_trans_pct, mesh, 1e3 * seconds / max(len(reg), 1))


def sensor_row(name: str, data_dir: str | os.PathLike[str] = "data", seed: int = 0,
               cache: Path | None = None) -> dict[str, object]:
    """One terrain's row (module docstring); terrains are simulated when absent."""
    from alte.sim import ensure_terrain, get_terrain, true_poses
    from alte.sim.profile import PROFILES

    truth = true_poses(get_terrain(name), seed).positions
    row: dict[str, object] = {"terrain": name, "path_m": float(
        np.linalg.norm(np.diff(truth, axis=0), axis=1).sum())}
    for key, (profile, pose, deskew, method) in RUNS.items():
        folder = ensure_terrain(name, data_dir, seed, profile=PROFILES[profile])
        score = _score(folder, name, (pose, deskew, method), seed, cache)
        row |= {f"ate_{key}_m": score.ate_m, f"rpe_{key}_pct": score.rpe_pct,
                f"mesh_{key}_m": score.mesh_m, f"ms_per_scan_{key}": score.ms_per_scan}
    return row


def sensor_table(names: list[str], data_dir: str | os.PathLike[str] = "data",
                 seed: int = 0) -> pd.DataFrame:
    """Rows of :func:`sensor_row` for ``names``."""
    return pd.DataFrame([sensor_row(n, data_dir, seed) for n in names])
