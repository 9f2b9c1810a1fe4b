"""Figures of the test benchmark (thesis ch. 2): scene, trajectory, scans, cloud,
ground/clusters, pose history and the obstacle map.

3D views go to a pyvista plotter (off-screen unless interactive, see
:mod:`alte.lab.plot.render`); 2D plots are matplotlib figures. Helpers only draw
arrays they are given.

Attitude, stated once for every figure and text of alte (:func:`attitude_deg`, and
the ``--mount`` strings of :class:`alte.types.Mount`): **roll, pitch, yaw in degrees
are intrinsic z-y-x angles** (yaw about z, then pitch about the new y, then roll
about the new x: the aerospace convention), which is the same rotation as extrinsic
x-y-z angles (roll, pitch, yaw) about the fixed axes. Each angle wraps at +-180 deg,
as the motion-capture attitude of the thesis' experimental terrains does (2.2.4,
fig. 4.32).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd
from scipy.spatial.transform import Rotation

from alte.lab.plot.arrays import Bools, Floats, Ints
from alte.lab.plot.figure import Caption, Plot, View
from alte.lab.plot.render import view
from alte.types import Trajectory

if TYPE_CHECKING:
    import pyvista as pv
    from pyvista.plotting._typing import ColormapOptions

#: Attitude angle names in the one convention of the module docstring.
ANGLE_NAMES = ("roll", "pitch", "yaw")


def attitude_deg(quaternions: Floats) -> Floats:
    """(F, 3) roll, pitch, yaw in degrees (intrinsic z-y-x; module docstring)."""
    rot = Rotation.from_quat(np.asarray(quaternions, dtype=np.float64).reshape(-1, 4))
    return rot.as_euler("ZYX", degrees=True)[:, ::-1]

__all__ = [
    "ANGLE_NAMES",
    "MISSION_TRAJECTORY",
    "POSE",
    "POSE_HISTORY",
    "TRAJECTORY",
    "add_cloud",
    "add_ground_and_clusters",
    "add_scene",
    "attitude_deg",
    "cloud_view",
    "clusters_view",
    "plot_obstacle_map",
    "plot_pose_history",
    "plot_scans",
    "plot_trajectory",
    "scene_view",
]

SCENE = Caption("Scene", "Ground-truth mesh, coloured by object class.")
REGISTERED_CLOUD = Caption("Registered cloud (fig. 2.9)",
                           "All scans registered into the inertial frame.")
GROUND_AND_CLUSTERS = Caption("Ground and obstacles (fig. 2.10)",
                              "MSAC ground plane and the Euclidean clusters above it.")
#: The test benchmark's trajectory (the default of :func:`plot_trajectory`).
MISSION_TRAJECTORY = Caption("Mission trajectory (fig. 2.7)",
                             "Vehicle positions and sensor origins over the mission.")
#: A terrain's trajectory (chapter 4).
TRAJECTORY = Caption("Trajectory", "The vehicle's path over {TERRAIN}.")
SCANS = Caption("Four scans (fig. 2.8)", "Scans at four times, each registered alone with eq. 2.2.")
#: The test benchmark's pose history (the default of :func:`plot_pose_history`).
POSE_HISTORY = Caption("Position and attitude (fig. 4.2)", "Position and attitude against time.")
#: A terrain's pose history (chapter 4).
POSE = Caption("Position and attitude", "Position and attitude against time.")
OBSTACLE_MAP = Caption("Obstacle map (fig. 3.13)", "Centroid and radius of every obstacle cluster.")


def add_scene(plotter: pv.Plotter, vertices: Floats, triangles: Ints,
              class_ids: Ints, *, class_names: Sequence[str],
              opacity: float = 1.0) -> pv.PolyData:
    """Add a ground-truth mesh coloured by object class (one mesh, per-face scalars)."""
    import pyvista as pv

    faces = np.column_stack([np.full(len(triangles), 3), triangles]).ravel()
    mesh = pv.PolyData(np.asarray(vertices, dtype=np.float64), faces)
    mesh.cell_data["class"] = np.asarray(class_ids)
    plotter.add_mesh(mesh, scalars="class", cmap="tab20", opacity=opacity,
                     clim=[0, len(class_names) - 1], show_scalar_bar=False)
    return mesh


def add_cloud(plotter: pv.Plotter, points: Floats, scalars: Floats | Ints | None = None,
              point_size: float = 2.0, cmap: ColormapOptions = "viridis", *,
              show_scalar_bar: bool = True) -> None:
    """Add a point cloud coloured by ``scalars`` (default: height)."""
    import pyvista as pv

    cloud = pv.PolyData(np.asarray(points, dtype=np.float64))
    cloud["value"] = np.asarray(points[:, 2] if scalars is None else scalars, dtype=np.float64)
    plotter.add_mesh(cloud, scalars="value", cmap=cmap, point_size=point_size,
                     render_points_as_spheres=False, show_scalar_bar=show_scalar_bar)


def add_ground_and_clusters(plotter: pv.Plotter, points: Floats, ground: Bools,
                            labels: Ints) -> None:
    """Ground inliers in black, obstacle clusters coloured by label (thesis fig. 2.10)."""
    add_cloud(plotter, points[ground], scalars=np.zeros(int(ground.sum())), cmap="gray",
              show_scalar_bar=False)
    keep = ~ground & (labels >= 0)
    if keep.any():
        add_cloud(plotter, points[keep], scalars=labels[keep] % 20, cmap="tab20",
                  point_size=3.0, show_scalar_bar=False)


def scene_view(vertices: Floats, triangles: Ints, class_ids: Ints, *,
               class_names: Sequence[str], zoom: float = 1.0) -> View:
    """The ground-truth mesh coloured by object class (:func:`add_scene`), zoomed in."""
    scene = view(SCENE)
    add_scene(scene.plotter, vertices, triangles, class_ids, class_names=class_names)
    scene.plotter.zoom_camera(zoom)
    return scene


def cloud_view(points: Floats) -> View:
    """The registered cloud coloured by height (thesis fig. 2.9)."""
    cloud = view(REGISTERED_CLOUD)
    add_cloud(cloud.plotter, points)
    return cloud


def clusters_view(points: Floats, ground: Bools, labels: Ints) -> View:
    """Ground and obstacle clusters (:func:`add_ground_and_clusters`, thesis fig. 2.10)."""
    clusters = view(GROUND_AND_CLUSTERS)
    add_ground_and_clusters(clusters.plotter, points, ground, labels)
    return clusters


def plot_trajectory(positions: Floats, sensor: Floats | None = None,
                    title: str = "Mission trajectory", *,
                    caption: Caption = MISSION_TRAJECTORY) -> Plot:
    """3D trajectory of the body (and sensor) with start/end marks (thesis fig. 2.7)."""
    import matplotlib.pyplot as plt

    fig = plt.figure(figsize=(6.5, 5))
    ax = fig.add_subplot(projection="3d")
    ax.plot(*positions.T, color="tab:blue", label="body")
    if sensor is not None:
        ax.plot(*sensor.T, color="tab:orange", lw=0.8, label="sensor")
    ax.scatter(*positions[0], color="green", label="start")
    ax.scatter(*positions[-1], color="red", label="end")
    ax.set(xlabel="x [m]", ylabel="y [m]", zlabel="z [m]", title=title)
    ax.legend(loc="upper left")
    return Plot(fig, caption)


def plot_scans(scans: Sequence[Floats], times: Sequence[float],
               max_points: int = 4000) -> Plot:
    """Inertial scans at a few times, one 3D panel each (thesis fig. 2.8)."""
    import matplotlib.pyplot as plt

    n = len(scans)
    cols = 2 if n > 1 else 1
    rows = int(np.ceil(n / cols))
    fig = plt.figure(figsize=(5.5 * cols, 4.5 * rows))
    for i, (pts, t) in enumerate(zip(scans, times, strict=True)):
        ax = fig.add_subplot(rows, cols, i + 1, projection="3d")
        step = max(1, len(pts) // max_points)
        sub = pts[::step]
        ax.scatter(*sub.T, c=sub[:, 2], s=1, cmap="viridis")
        ax.set(title=f"t = {t:.1f} s ({len(pts)} points)", xlabel="x", ylabel="y", zlabel="z")
    fig.tight_layout()
    return Plot(fig, SCANS)


def plot_pose_history(trajectory: Trajectory, title: str = "", *,
                      caption: Caption = POSE_HISTORY) -> Plot:
    """Position and attitude against time (thesis figs. 4.2, 4.26, 4.32; the angle
    convention is the module docstring's)."""
    import matplotlib.pyplot as plt

    fig, (top, bottom) = plt.subplots(2, 1, figsize=(8, 5.5), sharex=True)
    times = trajectory.times
    for i, axis in enumerate("xyz"):
        top.plot(times, trajectory.positions[:, i], label=axis)
    angles = attitude_deg(trajectory.quaternions)
    for i, name in enumerate(ANGLE_NAMES):
        bottom.plot(times, angles[:, i], label=name)
    top.set(ylabel="position [m]", title=title)
    bottom.set(ylabel="attitude [deg]", xlabel="time [s]")
    top.legend(loc="upper right")
    bottom.legend(loc="upper right")
    return Plot(fig, caption)


def plot_obstacle_map(points: Floats, obstacles: pd.DataFrame,
                      ground: Bools | None = None, max_points: int = 50_000) -> Plot:
    """Top view: points, obstacle centroids and radius circles (thesis fig. 3.13).

    ``obstacles`` has columns ``x``, ``y``, ``radius`` (``alte.ground.clustering.obstacle_map``).
    """
    import matplotlib.pyplot as plt
    from matplotlib.collections import PatchCollection
    from matplotlib.patches import Circle

    fig, ax = plt.subplots(figsize=(6.5, 6))
    step = max(1, len(points) // max_points)
    pts = points[::step]
    colour = "0.75" if ground is None else np.where(ground[::step], "0.8", "tab:blue")
    ax.scatter(pts[:, 0], pts[:, 1], s=0.5, c=colour)
    circles = [Circle((x, y), r) for x, y, r in zip(obstacles["x"], obstacles["y"],
                                                     obstacles["radius"], strict=True)]
    ax.add_collection(PatchCollection(circles, facecolor="none", edgecolor="tab:red", lw=1.5))
    ax.scatter(obstacles["x"], obstacles["y"], marker="+", color="tab:red", s=60)
    ax.set(aspect="equal", xlabel="x [m]", ylabel="y [m]",
           title=f"Obstacle map: {len(circles)} obstacles")
    return Plot(fig, OBSTACLE_MAP)
