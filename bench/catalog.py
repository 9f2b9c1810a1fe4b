"""The benchmark's rows by number: what each one compares.

This is the registry ``alte bench --help`` lists and :data:`bench.runner.ROWS`
attaches the measuring functions to. It imports nothing, so the command line can read
it without loading the rows' peers (open3d, pyoctomap, kiss-icp ...).
"""

from __future__ import annotations

__all__ = ["TITLES", "describe"]

#: Row number -> what it compares.
TITLES: dict[int, str] = {
    1: "Octomap native vs pyoctomap insertPointCloud",
    2: "Octomap native memory vs memoryUsage()",
    3: "batch builds vs numpy.argsort floor",
    4: "HD/MHD vs open3d compute_point_cloud_distance",
    5: "per-frame insert latency vs one 10 Hz rotation",
    6: "grid average / MSAC / clustering vs open3d",
    7: "scaling 10^4..10^7 points",
    8: "make report wall time vs thesis MATLAB",
    9: "alte map peak RSS: a mission flown 4x vs once",
    10: "alte map BAG: wall time vs mission time, per-frame latency",
    11: "Octomap native vs DUFOMap (UFOMap) scan integration",
    12: "odometry / refinement per real scan vs kiss-icp's pipeline",
    13: "sweep runs per core-second (20 scans, whole missions) and the grid's time",
    14: "a real LiDAR tile imported and flown vs a built-in mission simulated",
    15: "ground stage per real tile vs pysmrf and CSF (CPU s)",
    16: "LIO per simulated UAV scan vs kiss-icp's pipeline (CPU ms)",
}


def describe() -> str:
    """One line per row, ``- row N: title``, for help texts (a list in the docs too)."""
    return "\n".join(f"- row {number}: {title}" for number, title in sorted(TITLES.items()))
