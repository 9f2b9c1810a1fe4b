"""The sensor study in the report: its parameters in chapter 5 and its key table."""

from __future__ import annotations

from alte.lab.entry import KeyTable
from alte.types import JSONDict

__all__ = ["FULL_PARAMETERS", "KEY_TABLES", "SENSOR_SEEDS", "SENSOR_SEEDS_ALL", "UAV_MISSIONS"]

#: The simulated UAV missions (the realistic sensor's table in chapter 5).
UAV_MISSIONS: tuple[str, ...] = ("sim_nav_1", "sim_nav_2", "sim_lan_1", "sim_lan_2")
#: Simulation seeds of the sensor study in a full report: seed 0 alone (its whole UAV
#: missions cost ~60 CPU s each, KISS-ICP and LIO over every scan; two of them are the
#: grid's uav_lio missions, aligned once for both, see :mod:`alte.pipeline.posecache`), to
#: keep ``make report`` short on 2 cores; ``make report-full`` (or
#: ``--param SENSOR_SEEDS=[0,1,2]``) runs :data:`SENSOR_SEEDS_ALL` for the worst seed.
SENSOR_SEEDS: tuple[int, ...] = (0,)
SENSOR_SEEDS_ALL: tuple[int, ...] = (0, 1, 2)
#: The chapter 5 notebook's sensor parameters in a full report (quick: its defaults).
FULL_PARAMETERS: JSONDict = {"SENSOR_TERRAINS": list(UAV_MISSIONS), "SENSOR_RUNS": None,
                             "SENSOR_FRAMES": None, "SENSOR_SEEDS": list(SENSOR_SEEDS)}

KEY_TABLES: tuple[KeyTable, ...] = (
    KeyTable("sensor", "The realistic UAV sensor: poses and cloud per mission",
             "Per UAV mission and way of posing the scans: ATE (m and % of the path) and RPE "
             "(% per metre, 1 m segments) against the simulator's truth after rigid "
             "alignment, the registered cloud's mean distance to the true mesh, and the CPU "
             "time per scan (the pose step alone for odometry, as measured when the "
             "mission was aligned, also when its poses were read from the cache; CPU, not "
             "wall time, so that the machine's load does not enter): means over the "
             "simulation seeds ('seeds'), with the worst seed's ATE and mesh distance beside "
             "them. Thesis sensor: the instantaneous scan; UAV sensor: each firing at its own "
             "instant, per-point time, an IMU.",
             key=False, rank=60),
)
