"""Trial of LiDAR-inertial odometry on a simulated ``uav`` terrain folder: alte's own
(``alte``: :mod:`alte.registration.lio` through ``odometry_frames``, its defaults or
``KEY=VALUE`` settings of ``--odometry-set``) and the PyPI packages.

The packages are not part of alte (neither is a dependency: both diverged on the simulated
UAV missions, see environment.md); kept so the finding can be re-measured. They need
``pip install rko-lio==0.4.0 genz-lio==0.1.1`` in the venv. Usage:

    alte simulate sim_nav_1 --profile uav --out /tmp/uav
    python bench/lio_trial.py /tmp/uav/sim_nav_1-uav sim_nav_1 alte [plane_sigma=0.05 ...]
    python bench/lio_trial.py /tmp/uav/sim_nav_1-uav sim_nav_1 rko
    python bench/lio_trial.py /tmp/uav/sim_nav_1-uav sim_nav_1 genz

Every scan is scored (the pipeline's sensor study scores the scans kept in the control
volume), the odometry anchored at the true pose of the first scan.

Prints the time per scan and the ATE (RMSE after rigid alignment) and RPE (translation
error over 1 s per metre) of the body trajectory against the simulator's truth.
"""

from __future__ import annotations

import json
import sys
import time
from importlib.resources import files
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from alte.io.bags.bag import FrameStream, ReadSettings
from alte.io.bags.imu import ImuSamples, read_imu
from alte.metrics.trajectory import trajectory_errors
from alte.registration import odometry
from alte.registration.odometry import PoseCounts, odometry_frames, odometry_params, pose_matrix
from alte.sim import get_terrain, true_poses
from alte.sim.mission import TruePoses
from alte.types import Mount


def _rko(stream: FrameStream, imu: ImuSamples, mount: Mount) -> list[tuple[int, np.ndarray]]:
    from rko_lio.config import LIOConfig
    from rko_lio.lio import LIO

    lio = LIO(LIOConfig())
    t_imu, t_lidar = pose_matrix(mount.translation, mount.quaternion), \
        pose_matrix(stream.mount.translation, stream.mount.quaternion)
    k, out = 0, []
    for f in stream:
        end = f.stamp + 100_000_000
        while k < len(imu) and imu.stamps[k] < end:
            lio.add_imu_measurement(imu.linear_acceleration[k], imu.angular_velocity[k],
                                    int(imu.stamps[k]), t_imu)
            k += 1
        stamps = f.stamp + np.round(f.times * 1e9).astype(np.int64)
        try:
            lio.register_scan(f.points, stamps, t_lidar, start_time_ns=f.stamp, end_time_ns=end)
        except Exception as err:  # rko-lio gives up when ICP finds no correspondences
            print(f"rko-lio stopped at scan {len(out)}: {err}")
            break
        out.append((f.stamp, lio.pose()))
    return out


def _genz(stream: FrameStream, imu: ImuSamples, mount: Mount) -> list[tuple[int, np.ndarray]]:
    import genz_lio.genz_lio_pybind as genz
    from genz_lio.config import load_config

    config = load_config(files("genz_lio") / "configs/default/velodyne.yaml")
    t_imu = pose_matrix(mount.translation, mount.quaternion)
    lidar_in_imu = np.linalg.inv(t_imu) @ pose_matrix(stream.mount.translation,
                                                      stream.mount.quaternion)
    config.mapping.extrinsic_t, config.mapping.extrinsic_r = lidar_in_imu[:3, 3], \
        lidar_in_imu[:3, :3]
    config.preprocess.scan_line, config.preprocess.blind_min = 16, 0.5
    odometry = genz.GenZLIO(config)
    table = np.column_stack([imu.stamps / 1e9, imu.linear_acceleration, imu.angular_velocity])
    k, out = 0, []
    for f in stream:
        begin = f.stamp / 1e9
        j = int(np.searchsorted(table[:, 0], begin + 0.1, side="right"))
        result = odometry.register_scan(f.points, begin, begin + 0.1, table[k:j],
                                        timestamps=f.times)
        k = j
        if result.valid:
            out.append((f.stamp, result.pose @ np.linalg.inv(t_imu)))
    return out


def _alte(stream: FrameStream, imu: ImuSamples, truth: TruePoses,
          settings: dict[str, str]) -> list[tuple[int, np.ndarray]]:
    """``lio.FIELD=VALUE`` settings set a :class:`LioSettings` field that ``--odometry-set``
    does not reach (trials of the filter's internals)."""
    fields = {k[4:]: v for k, v in settings.items() if k.startswith("lio.")}
    settings = {k: v for k, v in settings.items() if not k.startswith("lio.")}
    if fields:
        base = odometry.lio_settings
        odometry.lio_settings = lambda params: base(params).replace(**fields)  # type: ignore[assignment]
    counts = PoseCounts()
    frames = odometry_frames(stream, stream.mount, counts=counts, imu=imu,
                             params=odometry_params("lio", settings),
                             start=(truth.positions[0], truth.quaternions[0]))
    return [(f.stamp, pose_matrix(f.position, f.quaternion)) for f in frames]


def main(folder: str, name: str, package: str, *settings: str) -> None:
    """Run one package over the terrain's bag and print the scores."""
    bag = Path(folder) / "bag"
    stream = FrameStream(bag, ReadSettings(pose_topic="", allow_no_pose=True))
    imu = read_imu(bag)
    seed = int(json.loads((Path(folder) / "scenario.json").read_text()).get("seed", 0))
    truth = true_poses(get_terrain(name), seed)
    start = time.perf_counter()
    if package == "alte":
        poses = _alte(stream, imu, truth, dict(s.split("=", 1) for s in settings))
    else:
        poses = (_rko if package == "rko" else _genz)(stream, imu, imu.mount or Mount())
    ms = 1e3 * (time.perf_counter() - start) / max(stream.scans, 1)
    stamps = np.array([s for s, _ in poses])
    index = np.searchsorted(truth.stamps, stamps)
    est = np.array([p[:3, 3] for _, p in poses])
    quat = Rotation.from_matrix(np.array([p[:3, :3] for _, p in poses])).as_quat()
    path = float(np.linalg.norm(np.diff(truth.positions, axis=0), axis=1).sum())
    errors = trajectory_errors(stamps, est, quat, truth.positions[index],
                               truth.quaternions[index])
    print(f"{package} {name}: {len(poses)}/{stream.scans} scans, {ms:.1f} ms/scan, "
          f"ATE {errors.ate_m:.2f} m on a {path:.0f} m path ({100 * errors.ate_m / path:.2f} %), "
          f"RPE {errors.rpe_trans_pct:.1f} %")


if __name__ == "__main__":
    main(*sys.argv[1:])
