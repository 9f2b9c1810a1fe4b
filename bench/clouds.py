"""Rows 4 and 6: point-cloud stages against Open3D on the same arrays.

Row 4: HD and MHD in both directions (:func:`alte.metrics.hausdorff`) between the
registered cloud and a map's corner set, against two ``compute_point_cloud_distance``
calls. Row 6: grid-average down-sampling, the MSAC ground plane and Euclidean
clustering against ``voxel_down_sample``, ``segment_plane`` and ``cluster_dbscan``
(``min_points=1`` makes DBSCAN exactly Euclidean clustering). Open3D point clouds
are built once, outside the timed calls: the peer is timed on its own data layout.
"""

from __future__ import annotations

from functools import partial
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from alte.lab.studies.thesis.numbers import mapper_params
from alte.types import JSONDict
from bench.core import LIMITS, Context, Result
from bench.maps import NAV, mapper_setup, octomap_passes
from bench.timing import measure
from bench.workload import Points

if TYPE_CHECKING:
    import open3d as o3d

    from alte.mappers import Mapper
    from bench.timing import Sample

__all__ = ["CLUSTER_TOLERANCE", "OBSTACLE_HEIGHT", "PLANE_THRESHOLD", "cloud_stages",
           "corner_sets", "hausdorff_speed", "open3d_hausdorff"]

#: MSAC / RANSAC inlier distance (m), the ground module's default.
PLANE_THRESHOLD = 0.1
#: Obstacle points rise this far over the ground plane (m; thesis 3.3.1).
OBSTACLE_HEIGHT = 0.3
#: Euclidean clustering distance (m) = DBSCAN ``eps``.
CLUSTER_TOLERANCE = 0.5


def _pcd(points: Points) -> o3d.geometry.PointCloud:
    import open3d as o3d

    return o3d.geometry.PointCloud(o3d.utility.Vector3dVector(np.asarray(points, np.float64)))


def open3d_hausdorff(pa: o3d.geometry.PointCloud, pb: o3d.geometry.PointCloud
                     ) -> tuple[float, float]:
    """HD and MHD from Open3D's nearest distances in both directions."""
    d_ab = np.asarray(pa.compute_point_cloud_distance(pb))
    d_ba = np.asarray(pb.compute_point_cloud_distance(pa))
    return max(d_ab.max(), d_ba.max()), max(d_ab.mean(), d_ba.mean())


def corner_sets(ctx: Context) -> dict[str, Points]:
    """Corners of the occupied cells of Octomap (native) and 3D-ALTE maps of sim_nav_1."""
    from alte.mappers import Alte3D, Octomap, make_mapper

    def octomap() -> Mapper:
        if ctx.has("octomap-passes"):
            return octomap_passes(ctx).maps["native"]
        mapper = mapper_setup(ctx, Octomap).make()
        for points, origin in ctx.scans(NAV):
            mapper.insert(points, origin)
        return mapper

    alte3d = make_mapper(Alte3D, mapper_params(NAV)["alte3d"])
    alte3d.build(ctx.workload(NAV).cloud)
    return {"octomap": ctx.memo("octomap-native-map", octomap).corners(),
            "alte3d": alte3d.corners()}


def hausdorff_speed(ctx: Context) -> list[Result]:
    """Row 4: our KD-tree HD/MHD vs Open3D distances, cloud <-> corner set."""
    from alte.metrics import hausdorff

    cloud = ctx.workload(NAV).cloud
    out = []
    for name, corners in corner_sets(ctx).items():
        pa, pb = _pcd(cloud), _pcd(corners)
        times = measure({"ours": partial(hausdorff, cloud, corners),
                         "peer": partial(open3d_hausdorff, pa, pb)},
                        ctx.config.repeats, ctx.config.warmup)
        ours = hausdorff(cloud, corners)
        hd, mhd = open3d_hausdorff(pa, pb)
        detail: JSONDict = {"points_a": len(cloud), "points_b": len(corners), "hd_m": ours.hd,
                            "mhd_m": ours.mhd, "hd_open3d_m": hd, "mhd_open3d_m": mhd,
                            **{k: s.as_dict() for k, s in times.items()}}
        ratio = times["ours"].median / times["peer"].median
        out.append(Result(4, f"HD+MHD both ways, cloud vs {name} corners",
                          times["ours"].median, times["peer"].median, "s",
                          f"ratio <= {LIMITS[4]:g}", bool(ratio <= LIMITS[4]), detail))
    return out


def _stage(case: str, times: dict[str, Sample], detail: JSONDict) -> Result:
    ours, peer = times["ours"].median, times["peer"].median
    summary = {k: s.as_dict() for k, s in times.items()}
    return Result(6, case, ours, peer, "s", "ratio <= 2 (else reason in note)",
                  bool(ours / peer <= LIMITS[6]), {**detail, **summary})


def cloud_stages(ctx: Context) -> list[Result]:
    """Row 6: grid average, MSAC plane, Euclidean clusters vs their Open3D counterparts."""
    import open3d as o3d

    from alte.ground import fit_plane_msac, obstacle_mask
    from alte.ground.clustering import euclidean_clusters
    from alte.registration.grid import grid_average

    work, cfg = ctx.workload(NAV), ctx.config
    raw, _ = work.stacked()
    p_raw, p_cloud = _pcd(raw), _pcd(work.cloud)

    def ransac() -> tuple[NDArray[np.float64], list[int]]:
        o3d.utility.random.seed(0)
        return p_cloud.segment_plane(PLANE_THRESHOLD, 3, 1000)

    grid = measure({"ours": lambda: grid_average(raw, work.voxel),
                    "peer": lambda: p_raw.voxel_down_sample(work.voxel)}, cfg.repeats, cfg.warmup)
    plane = measure({"ours": lambda: fit_plane_msac(work.cloud, threshold=PLANE_THRESHOLD),
                     "peer": ransac}, cfg.repeats, cfg.warmup)
    fit = fit_plane_msac(work.cloud, threshold=PLANE_THRESHOLD)
    obstacles = work.cloud[obstacle_mask(work.cloud, fit, OBSTACLE_HEIGHT)]
    p_obs = _pcd(obstacles)
    clusters = measure({"ours": lambda: euclidean_clusters(obstacles, CLUSTER_TOLERANCE),
                        "peer": lambda: p_obs.cluster_dbscan(CLUSTER_TOLERANCE, 1)},
                       cfg.repeats, cfg.warmup)
    labels = np.asarray(p_obs.cluster_dbscan(CLUSTER_TOLERANCE, 1))
    return [
        _stage(f"grid average {work.voxel} m, {len(raw)} pts", grid,
               {"cells_ours": len(grid_average(raw, work.voxel)),
                "cells_open3d": len(p_raw.voxel_down_sample(work.voxel).points)}),
        _stage(f"MSAC plane {PLANE_THRESHOLD} m, {len(work.cloud)} pts", plane,
               {"normal_ours": fit.normal.tolist(),
                "normal_open3d": list(ransac()[0][:3])}),
        _stage(f"Euclidean clusters {CLUSTER_TOLERANCE} m, {len(obstacles)} pts", clusters,
               {"clusters_ours": int(euclidean_clusters(obstacles, CLUSTER_TOLERANCE).max() + 1),
                "clusters_open3d": int(labels.max() + 1) if labels.size else 0}),
    ]
