"""Row 16: LiDAR-inertial odometry per simulated UAV scan, beside KISS-ICP's own pipeline.

The realistic UAV sensor (``alte simulate sim_lan_2 --profile uav``: each firing at its
own instant, per-point time, an IMU at 200 Hz) flies the whole ``sim_lan_2`` mission (the
first 60 scans in quick mode). On one core, alte's LIO (:mod:`alte.registration.lio`,
``odometry_frames`` with the bag's IMU: the pose step chapter 5's sensor study and the
grid's ``uav_lio`` ablation run on every scan of six to eight missions) against
``kiss_icp``'s own ``KissICP`` with its default configuration, fed the same scans in the
same run. Times are the process's CPU time per scan (row 12's clock: every thread, a scan
from its entry into the stream to the next one's), mean and median. Target: the mean under
100 ms per scan (a 10 Hz sensor); the ratio to the peer is informative (the LIO fits
planes to 20 neighbours and iterates a Kalman update; KISS-ICP registers point to point).
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator

import numpy as np

from alte.io.bags.imu import ImuSamples, read_imu
from alte.types import Frame, JSONDict
from bench.core import Context, Result
from bench.poses import BUDGET_MS, _Clock, _peer
from bench.timing import one_core

__all__ = ["lio_speed"]

#: The mission flown and the scans of it in quick mode (the LIO needs consecutive scans).
MISSION, QUICK_SCANS = "sim_lan_2", 60


def _mission(ctx: Context) -> tuple[list[Frame], ImuSamples]:
    """The UAV mission's scans (with per-point time) and its IMU samples, read once."""
    from alte.io.bags.bag import read_frames
    from alte.sim import ensure_terrain
    from alte.sim.profile import PROFILES

    def load() -> tuple[list[Frame], ImuSamples]:
        folder = ensure_terrain(MISSION, ctx.config.data_dir, profile=PROFILES["uav"])
        limit = QUICK_SCANS if ctx.config.quick else None
        return read_frames(folder / "bag").frames[:limit], read_imu(folder / "bag")
    return ctx.memo("uav_mission", load)


def _lio(frames: list[Frame], imu: ImuSamples, clock: _Clock) -> None:
    from alte.registration.odometry import OdometrySettings, PoseCounts, odometry_frames
    from alte.types import Mount

    params = OdometrySettings.parse({"method": "lio"})

    def stream(scans: Iterable[Frame]) -> Iterator[Frame]:
        return odometry_frames(scans, Mount(), counts=PoseCounts(), params=params, imu=imu)
    clock.run(frames, stream)


def lio_speed(ctx: Context) -> list[Result]:
    """Row 16 (module docstring)."""
    frames, imu = _mission(ctx)
    clocks = {"kiss-icp": _Clock(), "lio": _Clock()}
    with one_core():
        for _ in range(max(1, ctx.config.repeats // 5)):
            _peer(frames, clocks["kiss-icp"])
            _lio(frames, imu, clocks["lio"])
    mean = {k: float(np.mean(c.cpu)) for k, c in clocks.items()}
    median = {k: float(np.median(c.cpu)) for k, c in clocks.items()}
    detail: JSONDict = {
        "scans": len(frames), "points_per_scan": int(np.median([len(f.points) for f in frames])),
        "cpu_ms_mean": mean, "cpu_ms_median": median,
        "cpu_ms_p90": {k: float(np.percentile(c.cpu, 90)) for k, c in clocks.items()}}
    scans = f"{MISSION} UAV ({len(frames)} scans)"
    title = "LIO per simulated UAV scan vs kiss-icp pipeline"
    return [Result(16, f"{title}, {stat}, {scans}", value["lio"], value["kiss-icp"], "ms",
                   f"< {BUDGET_MS:g} ms", bool(value["lio"] < BUDGET_MS), detail)
            for stat, value in (("mean", mean), ("median", median))]
