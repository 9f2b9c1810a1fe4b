"""Chapter 5 in the report: the thesis' sweeps, the trade-off grid, its ablations, the
sensor study; the grid's key tables."""

from __future__ import annotations

from alte.lab.entry import QUICK_FRAMES, Entry, KeyTable
from alte.lab.studies.sensor import report as sensor

__all__ = ["ENTRIES", "KEY_TABLES"]

ENTRIES: tuple[Entry, ...] = (
    Entry("ch5_analysis", "ch5_analysis.ipynb", {"FRAMES": QUICK_FRAMES},
          {"FRAMES": None, "ROWS": None, "GRID_SPEC": "notebooks/sweeps/tradeoff.yaml",
           "SCHEDULER": "local", "WORKERS": 2, **sensor.FULL_PARAMETERS},
          terrains=("sim_nav_1", "sim_lan_2", "sim_nav_2"), first=True,
          title="Chapter 5: analysis"),
)

_RULE = ("Each mapper's map picked from our sweep by the thesis' comparison rule, beside the "
         "thesis' choice. Times are CPU seconds known within their spread: maps the rule "
         "cannot separate within it are all shown (rule_pick: tie).")
KEY_TABLES: tuple[KeyTable, ...] = (
    KeyTable("table_5_10", "Table 5.10: best 2D maps by the thesis' rule", _RULE, rank=10),
    KeyTable("table_5_11", "Table 5.11: best 3D maps by the thesis' rule", _RULE, rank=20),
    KeyTable("key_equal_size", "MHD at equal size",
             "The MHD each mapper reaches at 1,000 / 5,000 / 20,000 basis functions, read "
             "off its Pareto front (only where its maps reach that size); mean over seeds "
             "with the 95 % bootstrap interval. Every metric: equal_size.csv.", key=False,
             rank=30),
    KeyTable("key_equal_fidelity", "Size at equal MHD",
             "The basis functions each mapper needs for the same MHD (three levels inside "
             "both fronts' range per terrain); mean over seeds with the 95 % bootstrap "
             "interval. Memory and time too: equal_fidelity.csv.", key=False, rank=40),
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
             key=False, hide=("claim",), rows=80, rank=50),
)
