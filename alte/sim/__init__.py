"""Test benchmark (thesis ch. 2): a simulated VLP-16 over the thesis' eight terrains.

Each terrain (:data:`TERRAINS`) is a triangle mesh with per-triangle object ids,
scanned along its mission by a ray-cast VLP-16 and written as a ROS 2 bag with its
ground truth: ``ensure_terrain(name)`` makes ``data/NAME/`` (cached by spec and seed),
``load_scenario(folder)`` reads it back.
"""

from alte.sim.groundtruth import load_ground_truth, mesh_distance, write_ground_truth
from alte.sim.mission import Simulation, TruePoses, simulate, true_poses
from alte.sim.platform import (
    Cart,
    Quadrotor,
    Trajectory,
    tripod_mount,
)
from alte.sim.scenario import (
    Scenario,
    ensure_terrain,
    get_terrain,
    load_scenario,
    spec_hash,
    terrain_folder,
    write_scenario,
)
from alte.sim.scene import CLASSES, Scene, SceneBuilder
from alte.sim.sensor import VLP16
from alte.sim.terrains import TERRAINS, Terrain, TerrainSpec

__all__ = [
    "CLASSES",
    "TERRAINS",
    "VLP16",
    "Cart",
    "Quadrotor",
    "Scenario",
    "Scene",
    "SceneBuilder",
    "Simulation",
    "Terrain",
    "TerrainSpec",
    "Trajectory",
    "TruePoses",
    "ensure_terrain",
    "get_terrain",
    "load_ground_truth",
    "load_scenario",
    "mesh_distance",
    "simulate",
    "spec_hash",
    "terrain_folder",
    "tripod_mount",
    "true_poses",
    "write_ground_truth",
    "write_scenario",
]
