"""The realistic UAV sensor against the thesis' instantaneous scan, per terrain.

For each UAV mission (or any terrain) the ``uav`` sensor profile's bag is registered
with recorded poses as taken, recorded poses + deskew, LiDAR-only odometry (KISS-ICP) and
LiDAR-inertial odometry (:mod:`alte.registration.lio`, the bag's IMU), beside the thesis
profile's bag with recorded poses (the chapters' reference), and scored
against the simulator's truth: ATE and RPE (translation, % of 1 m segments) as evo reports
them (:mod:`alte.metrics.trajectory`) and the merged cloud's mean distance to the true
mesh, with the CPU time per scan (``cpu_ms_per_scan``: for odometry the pose step's own
CPU, :attr:`~alte.registration.settings.PoseCounts.cpu_seconds`, which a cached alignment
carries from the run that made it; else the registration's CPU in this process). CPU, not
wall time: a cached alignment was timed under another moment's load.
"""

from __future__ import annotations

import os
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from alte.errors import ParameterError
from alte.lab.studies.experiments import CACHE_DIR
from alte.metrics.trajectory import trajectory_errors
from alte.pipeline import FrameSettings, PoseSource, open_input, prepare
from alte.pipeline.prepare import POSE_DIR
from alte.registration.odometry import odometry_params

__all__ = ["RUNS", "RUN_TEXT", "sensor_row", "sensor_table", "sensor_view"]

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
    cpu_ms_per_scan: float


def _score(folder: Path, name: str, spec: FrameSettings, seed: int, *,
           cache: Path | None, poses: Path) -> _Score:
    from alte.sim import get_terrain, load_ground_truth, mesh_distance, true_poses

    start = time.process_time()
    reg = prepare(open_input(folder), spec, cache=cache, pose_cache=poses)
    cpu = time.process_time() - start
    if spec.poses is PoseSource.ODOMETRY:  # the pose step alone, as `alte register` says
        cpu = reg.counts.poses.cpu_seconds / max(reg.counts.poses.frames, 1) * len(reg)
    truth = true_poses(get_terrain(name), seed)
    traj = reg.trajectory
    index = np.searchsorted(truth.stamps, traj.stamps)
    tp, tq = truth.positions[index], truth.quaternions[index]
    mesh = float(mesh_distance(np.asarray(reg.cloud), load_ground_truth(folder)).mean())
    errors = trajectory_errors(traj.stamps, traj.positions, traj.quaternions, tp, tq)
    return _Score(errors.ate_m, errors.rpe_trans_pct, mesh, 1e3 * cpu / max(len(reg), 1))


def sensor_row(name: str, data_dir: str | os.PathLike[str] = "data", seed: int = 0, *,
               cache: Path | None = None, runs: Sequence[str] | None = None,
               frames: int | None = None) -> dict[str, object]:
    """One terrain's row (module docstring) for the ``runs`` named (keys of :data:`RUNS`,
    None: all);
    terrains are simulated when absent. ``frames``: that many evenly spaced scans (None:
    the whole mission); odometry still poses every scan of the whole mission (it aligns
    consecutive scans) and keeps those."""
    from alte.sim import ensure_terrain, get_terrain, true_poses
    from alte.sim.profile import PROFILES

    runs = tuple(RUNS) if runs is None else runs
    # Odometry's poses are kept per input and settings in the data folder's cache: the
    # sweep's LiDAR-inertial ablation poses two of the same missions (chapter 5 runs this
    # study first; the grid reads their poses).
    poses = Path(data_dir) / CACHE_DIR / POSE_DIR
    unknown = sorted(set(runs) - set(RUNS))
    if unknown:
        raise ParameterError(f"sensor runs {', '.join(unknown)}: valid: {', '.join(RUNS)}")
    truth = true_poses(get_terrain(name), seed).positions
    row: dict[str, object] = {"terrain": name, "seed": seed, "path_m": float(
        np.linalg.norm(np.diff(truth, axis=0), axis=1).sum())}
    for key in runs:
        profile, pose, deskew, method = RUNS[key]
        whole = pose is PoseSource.ODOMETRY
        folder = ensure_terrain(name, data_dir, seed, None if whole else frames,
                                profile=PROFILES[profile])
        spec = FrameSettings(frames=frames, poses=pose, deskew=deskew,
                         odometry=odometry_params(method))
        score = _score(folder, name, spec, seed, cache=cache, poses=poses)
        row |= {f"ate_{key}_m": score.ate_m, f"rpe_{key}_pct": score.rpe_pct,
                f"mesh_{key}_m": score.mesh_m, f"cpu_ms_per_scan_{key}": score.cpu_ms_per_scan}
    return row


def _row(item: tuple[str, int, tuple[str, ...] | None, int | None],
         data_dir: str) -> dict[str, object]:
    """:func:`sensor_row` of one (terrain, seed, runs, frames) item, on a worker."""
    name, seed, runs, frames = item
    return sensor_row(name, data_dir, seed, runs=runs, frames=frames)


def sensor_table(names: Sequence[str], data_dir: str | os.PathLike[str] = "data",
                 seed: int = 0, *, seeds: Sequence[int] | None = None,
                 runs: Sequence[str] | None = None, frames: int | None = None,
                 progress: bool = False, scheduler: str = "serial",
                 workers: int = 2) -> pd.DataFrame:
    """Rows of :func:`sensor_row` for ``names``, one per simulation seed of ``seeds``
    (None: ``seed`` alone), in that order, with a progress bar over terrains and seeds.
    ``scheduler`` and ``workers`` as for a sweep
    (:func:`~alte.lab.studies.sweep.runner.executor`): each terrain and seed is one task and
    touches its own folders; the first failure is raised."""
    from alte.lab.studies.sweep.runner import executor
    from alte.progress import bar as progress_bar

    if seeds is not None and len(seeds) == 0:
        raise ParameterError("sensor study: seeds is empty; give at least one seed "
                             "(None: the seed argument alone)")
    chosen = None if runs is None else tuple(runs)
    items = [(n, s, chosen, frames) for n in names
             for s in ((seed,) if seeds is None else seeds)]
    rows: list[dict[str, object]] = [{} for _ in items]
    with executor(scheduler, workers) as pool, \
            progress_bar(total=len(items), desc="sensor missions", unit="mission",
                         disable=not progress) as bar:
        for i, row, err in pool(_row, items, str(data_dir)):
            if err is not None:
                raise err
            rows[i] = row or {}
            bar.update()
    return pd.DataFrame(rows)


#: What each run of :data:`RUNS` is, in words (the report's table).
RUN_TEXT = {
    "thesis": "thesis sensor (instantaneous scan), recorded poses",
    "recorded": "UAV sensor, recorded poses, scans as taken",
    "deskew": "UAV sensor, recorded poses, scans deskewed",
    "lidar": "UAV sensor, LiDAR odometry (KISS-ICP)",
    "lio": "UAV sensor, LiDAR-inertial odometry (the bag's IMU)",
}


def sensor_view(table: pd.DataFrame) -> pd.DataFrame:
    """:func:`sensor_table` one row per terrain and run: means over the seeds with the
    worst seed's ATE and mesh distance beside them, units in the column names, rounded to
    what the measures resolve (mm, 0.1 mm on the mesh, 0.1 ms of CPU per scan)."""
    rows = []
    for terrain, here in table.groupby("terrain", sort=False):
        for key, text in RUN_TEXT.items():
            if f"ate_{key}_m" not in here:
                continue
            ate = here[f"ate_{key}_m"].astype(float)
            share = 100 * ate / here["path_m"].astype(float)
            mesh = here[f"mesh_{key}_m"].astype(float)
            rows.append({"terrain": terrain, "run": text, "seeds": len(here),
                         "ATE (m)": round(ate.mean(), 3),
                         "ATE (% of path)": round(share.mean(), 2),
                         "ATE, worst seed (% of path)": round(share.max(), 2),
                         "RPE (% per m)": round(here[f"rpe_{key}_pct"].astype(float).mean(), 2),
                         "cloud to true mesh, mean (m)": round(mesh.mean(), 4),
                         "cloud to true mesh, worst seed (m)": round(mesh.max(), 4),
                         "CPU per scan (ms)":
                             round(here[f"cpu_ms_per_scan_{key}"].astype(float).mean(), 1)})
    return pd.DataFrame(rows)
