"""Where the front page's words come from: chapter titles, figure captions, key tables.

Captions are looked up in this order (:func:`caption`):

1. the notebook's own ``results.json`` key ``"captions"``: ``{figure name: text}``, for a
   caption that depends on the run (a notebook captions what only it knows);
2. :data:`FIGURES`: per source notebook (its file stem), per figure name (the PNG's
   stem, as given to ``save_figure``/``show``); ``{TERRAIN}``-style fields are filled
   from the run's parameters;
3. otherwise the figure name in words, marked "no caption".

A test checks that every figure the notebooks save has an entry in :data:`FIGURES`.
Figures named with a prefix of :data:`TRADEOFF_PREFIXES` are shown in the front page's
trade-off section rather than under their chapter.
"""

from __future__ import annotations

import re
import string
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

__all__ = ["CHAPTERS", "FIGURES", "KEY_TABLES", "TRADEOFF_PREFIXES", "Caption", "KeyTable",
           "caption", "chapter_title"]

#: Figure-name prefixes of the trade-off figures (see :mod:`alte.plot.tradeoff`).
TRADEOFF_PREFIXES = ("tradeoff", "equal_size", "equal_fidelity")


@dataclass(frozen=True)
class Caption:
    """A figure's short title and its caption text."""

    title: str
    text: str


#: Chapter title per source notebook stem.
CHAPTERS: dict[str, str] = {
    "ch2_test_benchmark": "Chapter 2: the test benchmark on {TERRAIN}",
    "ch3_mapping_techniques": "Chapter 3: the four mapping techniques on {TERRAIN}",
    "ch4_terrain": "Chapter 4: terrain {TERRAIN}",
    "ch5_analysis": "Chapter 5: analysis",
    "ch6_real_data": "Chapter 6: real data",
    "ch7_sensitivity": "Beyond the thesis: parameter sensitivity",
    "ch7_landing": "Beyond the thesis: landing-site selection",
    "ch7_planning": "Beyond the thesis: path planning",
}

_FRONT = ("Each dot is one map (a parameter setting and seed); the line is the mapper's Pareto "
          "front (no other of its maps is both smaller and better) averaged over seeds, the "
          "band its 95 % bootstrap interval over seeds; the star marks the thesis' chosen "
          "setting. Size on a log axis, and errors and times too (they span decades over a "
          "grid); completeness on a linear one.")

#: Captions per source notebook stem and figure name.
FIGURES: dict[str, dict[str, Caption]] = {
    "ch2_test_benchmark": {
        "scene": Caption("Scene", "Ground-truth mesh, coloured by object class."),
        "trajectory": Caption("Mission trajectory (fig. 2.7)",
                              "Vehicle positions and sensor origins over the mission."),
        "scans": Caption("Four scans (fig. 2.8)",
                         "Scans at four times, each registered alone with eq. 2.2."),
        "registered_cloud": Caption("Registered cloud (fig. 2.9)",
                                    "All scans registered into the inertial frame."),
        "ground_and_clusters": Caption("Ground and obstacles (fig. 2.10)",
                                       "MSAC ground plane and the Euclidean clusters above it."),
        "pose_history": Caption("Position and attitude (fig. 4.2)",
                                "Position and attitude against time."),
        "obstacle_map": Caption("Obstacle map (fig. 3.13)",
                                "Centroid and radius of every obstacle cluster."),
    },
    "ch3_mapping_techniques": {
        "fig_3_3_quadtree_timelapse": Caption("Quadtree over time (fig. 3.3)",
                                              "Quadtree rebuilt as the scans arrive."),
        "fig_3_7_octomap_timelapse": Caption("Octomap over time (fig. 3.7)",
                                             "Octomap's occupied voxels as scans arrive."),
        "fig_3_14_alte2d_timelapse": Caption(
            "2D-ALTE over time (fig. 3.14)",
            "2D-ALTE's cells as scans arrive; right: the binary grid proposed in chapter 6."),
        "fig_3_17_alte3d_timelapse": Caption("3D-ALTE over time (fig. 3.17)",
                                             "3D-ALTE's occupied cells as scans arrive."),
        "basis_functions_over_time": Caption(
            "Basis functions against mission time",
            "Map size as the mission proceeds: 2D mappers left, 3D mappers right."),
    },
    "ch4_terrain": {
        "terrain": Caption("Terrain (figs. 4.1, 4.7, 4.13, ...)",
                           "The simulated terrain {TERRAIN} and its control volume."),
        "pose": Caption("Position and attitude", "Position and attitude against time."),
        "trajectory": Caption("Trajectory", "The vehicle's path over {TERRAIN}."),
        "cloud": Caption("Registered cloud", "The registered point cloud of {TERRAIN}."),
        "maps": Caption("Maps with the chapter 4 parameters",
                        "The two mappers of this case with the thesis' chapter 4 parameters."),
    },
    "ch5_analysis": {
        "fig_5_2": Caption("Quadtree sweep (fig. 5.2)", "Quadtree maps over max_points."),
        "fig_5_3": Caption("Octomap sweep (fig. 5.3)", "Octomap maps over resolution."),
        "fig_5_4": Caption("2D-ALTE sweep (fig. 5.4)", "2D-ALTE maps for the thesis' settings."),
        "fig_5_5": Caption("3D-ALTE sweep (fig. 5.5)", "3D-ALTE maps for the thesis' settings."),
        "tradeoff_mhd": Caption("MHD against map size", _FRONT),
        "tradeoff_accuracy": Caption("Mean accuracy against map size",
                                     "Ground-truth accuracy (distance of each occupied cell to "
                                     "the true surface). " + _FRONT),
        "tradeoff_completeness": Caption("Completeness against map size",
                                         "Share of the true surface the map covers (higher is "
                                         "better: the front is the upper-left envelope). "
                                         + _FRONT),
        "tradeoff_height_rmse": Caption("Height RMSE against map size (2D maps)",
                                        "RMSE of the map height against the true top "
                                        "surface. " + _FRONT),
        "tradeoff_time": Caption("Mapping time against map size",
                                 "Time spent in the mapper calls only. " + _FRONT),
        "tradeoff_memory": Caption("MHD against memory", _FRONT),
        "tradeoff_obstacle_recall": Caption(
            "Obstacle recall against map size",
            "Share of the true obstacles the map shows (simulator objects standing at least "
            "the landing study's obstacle step above the ground, 0.3 m at urban scale and "
            "0.06 m in the lab, seen from above; higher is better). " + _FRONT),
        "tradeoff_obstacle_precision": Caption(
            "Obstacle precision against map size",
            "Share of the map's obstacles (connected areas more than that step above its "
            "ground) that lie on a true object (higher is better). " + _FRONT),
        "tradeoff_ablation_2d": Caption(
            "2D maps with one thing changed",
            "MHD against basis functions of Quadtree and 2D-ALTE on a landing terrain, one "
            "panel per ablation (base: the grid as specified; domain_data: root cell over "
            "the data; set_b_centers / set_b_occupied: another set B; occupancy_max: "
            "Quadtree's occupancy rule; min_pts_per_leaf: 3D-ALTE only; uav_deskew / "
            "uav_lio: the realistic UAV sensor, recorded poses deskewed or LiDAR-inertial "
            "odometry's poses), and the base grid "
            "against occupied cells. Fronts averaged over seeds with 95 % bootstrap bands."),
        "tradeoff_ablation_3d": Caption(
            "3D maps with one thing changed",
            "MHD against basis functions of Octomap and 3D-ALTE on a navigation terrain, one "
            "panel per ablation (see the 2D figure), and the base grid against occupied "
            "cells: Octomap's free leaves and 3D-ALTE's empty ones not counted. Fronts "
            "averaged over seeds with 95 % bootstrap bands."),
        "equal_size_2d": Caption("2D maps at equal size",
                                 "MHD each 2D mapper reaches at the same number of basis "
                                 "functions, read off its front; mean over seeds with 95 % "
                                 "bootstrap intervals."),
        "equal_size_3d": Caption("3D maps at equal size",
                                 "MHD each 3D mapper reaches at the same number of basis "
                                 "functions, read off its front; mean over seeds with 95 % "
                                 "bootstrap intervals."),
        "equal_fidelity_2d": Caption("2D maps at equal fidelity",
                                     "Basis functions each 2D mapper needs for the same MHD "
                                     "(log axis); mean over seeds with 95 % bootstrap "
                                     "intervals."),
        "equal_fidelity_3d": Caption("3D maps at equal fidelity",
                                     "Basis functions each 3D mapper needs for the same MHD "
                                     "(log axis); mean over seeds with 95 % bootstrap "
                                     "intervals."),
    },
    "ch6_real_data": {
        "fig_6_1_ground_filter": Caption("Ground filter (fig. 6.1)",
                                         "Ground filter errors on the ISPRS samples."),
        "tradeoff_real": Caption(
            "The fronts on a real sequence (balm_seq)",
            "Real scans mapped with their reference poses (bundle adjustment): every map one "
            "dot, the line each mapper's Pareto front (one recording: no seeds, no band). "
            "MHD is the thesis' metric against the cloud the map was made from; height RMSE, "
            "mean accuracy and completeness are measured against the reference cloud (every "
            "scan with its reference pose), the real stand-in for the simulator's truth."),
    },
    "ch7_landing": {
        "fig_landing_sites": Caption(
            "Landing sites on the maps",
            "Map height (grey: unknown), obstacles red, detected feasible centres inside the "
            "blue outline, truly feasible ones inside the dashed green one; circles are the "
            "chosen sites, green when truly safe and red when not."),
    },
    "ch7_planning": {
        "paths": Caption("Paths over the maps (top view)",
                         "Occupied cells by height; a line per policy; red dots: path samples "
                         "too close to the true mesh or inside a solid."),
        "paths_3d": Caption("Paths in 3D", "The planned paths over one terrain's map."),
    },
    "ch7_sensitivity": {
        "alte2d_kappa_max_res": Caption("2D-ALTE: kappa x max_res",
                                        "Each metric over the kappa x max_res grid."),
        "alte3d_min_pts_split_max_res": Caption(
            "3D-ALTE: min_pts_split x max_res", "Each metric over the min_pts_split x max_res "
            "grid."),
        "main_effects": Caption("Main effects",
                                "Each metric's mean at each level of each swept parameter."),
    },
}


@dataclass(frozen=True)
class KeyTable:
    """A CSV shown on the front page with the thesis' values beside ours."""

    name: str
    title: str
    text: str
    key: bool = True
    hide: tuple[str, ...] = ()
    rows: int = 60


#: The key tables, in the order the front page shows them.
KEY_TABLES: tuple[KeyTable, ...] = (
    KeyTable("table_5_10", "Table 5.10: best 2D maps by the thesis' rule",
             "Each mapper's map picked from our sweep by the thesis' comparison rule, beside "
             "the thesis' choice. Times are CPU seconds known within their spread: maps "
             "the rule cannot separate within it are all shown (rule_pick: tie)."),
    KeyTable("table_5_11", "Table 5.11: best 3D maps by the thesis' rule",
             "Each mapper's map picked from our sweep by the thesis' comparison rule, beside "
             "the thesis' choice. Times are CPU seconds known within their spread: maps "
             "the rule cannot separate within it are all shown (rule_pick: tie)."),
    KeyTable("key_equal_size", "MHD at equal size",
             "The MHD each mapper reaches at 1,000 / 5,000 / 20,000 basis functions, read "
             "off its Pareto front (only where its maps reach that size); mean over seeds "
             "with the 95 % bootstrap interval. Every metric: equal_size.csv.", key=False),
    KeyTable("key_equal_fidelity", "Size at equal MHD",
             "The basis functions each mapper needs for the same MHD (three levels inside "
             "both fronts' range per terrain); mean over seeds with the 95 % bootstrap "
             "interval. Memory and time too: equal_fidelity.csv.", key=False),
    KeyTable("ablation", "Ablations: what moves the verdicts",
             "Each claim's verdict on the thesis' two sweep terrains, first for the grid as "
             "specified (base), then with one thing changed: map size counted as occupied "
             "cells (size_occupied: Octomap's free and 3D-ALTE's empty leaves not counted), "
             "only the thesis' six settings per mapper (thesis_rows), the root cell over "
             "the data (domain_data), set B of cell centres (set_b_centers) or of occupied "
             "2D cells only (set_b_occupied), Quadtree's occupancy by the highest point "
             "(occupancy_max), 3D-ALTE's min_pts as a plain count per leaf "
             "(min_pts_per_leaf), the realistic UAV sensor with recorded poses and deskew "
             "(uav_deskew) or with LiDAR-inertial odometry's poses (uav_lio). 'moves' lists "
             "the changes that move the verdict; the quotes are in the claims table above.",
             key=False, hide=("claim",), rows=80),
    KeyTable("sensor", "The realistic UAV sensor: poses and cloud per mission",
             "Per UAV mission and way of posing the scans: ATE (m and % of the path) and RPE "
             "(% per metre, 1 m segments) against the simulator's truth after rigid "
             "alignment, the registered cloud's mean distance to the true mesh, and the time "
             "per scan (the pose step alone for odometry). Thesis sensor: the instantaneous "
             "scan; UAV sensor: each firing at its own instant, per-point time, an IMU.",
             key=False),
    KeyTable("table_5_7", "Table 5.7: Quadtree sweep", "Our maps beside the thesis' rows."),
    KeyTable("table_5_8", "Table 5.8: Octomap sweep", "Our maps beside the thesis' rows."),
    KeyTable("table_5_9", "Table 5.9: 2D-ALTE sweep", "Our maps beside the thesis' rows."),
    KeyTable("table_5_12", "Table 5.12: 3D-ALTE sweep", "Our maps beside the thesis' rows."),
    KeyTable("table_5_5", "Table 5.5: point cloud for the 3D analysis",
             "Frames and points of our registered cloud beside the thesis'."),
    KeyTable("table_5_6", "Table 5.6: point cloud for the 2D analysis",
             "Frames and points of our registered cloud beside the thesis'."),
)


class _Fields(dict[str, str]):
    def __missing__(self, key: str) -> str:
        return ""


def _fill(text: str, parameters: Mapping[str, Any]) -> str:
    """``text`` with ``{NAME}`` fields from ``parameters``; a missing field is dropped with
    the preposition before it ("cloud of {TERRAIN}." -> "cloud.")."""
    values = _Fields({k: str(v) for k, v in parameters.items()})
    filled = string.Formatter().vformat(text, (), values)
    filled = re.sub(r"\s+(?:of|on|in|for|over)?\s*(?=[.,;:]|$)", "", filled)
    return re.sub(r"\s{2,}", " ", filled).strip()


def chapter_title(notebook: str, run_name: str, parameters: Mapping[str, Any]) -> str:
    """The title of a run's section: its chapter's title, or the run name."""
    template = CHAPTERS.get(notebook)
    if template is None:
        return run_name.replace("_", " ")
    return _fill(template, parameters)


def caption(notebook: str, figure: str, parameters: Mapping[str, Any],
            own: Mapping[str, Any] | None = None) -> Caption:
    """The caption of ``figure`` of a run of ``notebook`` (see the module docstring)."""
    known = FIGURES.get(notebook, {}).get(figure)
    title = known.title if known else figure.replace("_", " ")
    if own and isinstance(own.get(figure), str):
        return Caption(title, own[figure])
    if known:
        return Caption(known.title, _fill(known.text, parameters))
    return Caption(title, "(no caption)")
