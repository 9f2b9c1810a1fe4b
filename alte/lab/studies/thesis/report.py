"""The thesis' chapters 2 to 4 in the report, and the sweep tables of chapter 5.

Chapters 2 and 3 run once, chapter 4 once per mission profile; tables 5.5-5.9 and 5.12
(our maps beside the thesis' rows, written by chapter 5) are shown among the key tables.
"""

from __future__ import annotations

from alte.lab.entry import QUICK_FRAMES, Entry, KeyTable
from alte.sim.terrains import TERRAINS as SIMULATED
from alte.types import JSONDict

__all__ = ["ENTRIES", "KEY_TABLES", "QUICK_TERRAINS", "TERRAINS"]

#: The eight mission profiles of chapter 4 (simulated and experimental, navigation and landing).
TERRAINS: tuple[str, ...] = tuple(SIMULATED)
#: Terrains chapter 4 is run on in quick mode (one navigation, one landing profile).
QUICK_TERRAINS: tuple[str, ...] = ("sim_nav_1", "sim_lan_1")


def _ch4(terrain: str) -> Entry:
    quick: JSONDict | None = ({"TERRAIN": terrain, "FRAMES": QUICK_FRAMES}
                              if terrain in QUICK_TERRAINS else None)
    return Entry(f"ch4_{terrain}", "ch4_terrain.ipynb", quick,
                 {"TERRAIN": terrain, "FRAMES": None}, title="Chapter 4: terrain {TERRAIN}")


ENTRIES: tuple[Entry, ...] = (
    Entry("ch2_test_benchmark", "ch2_test_benchmark.ipynb", {"FRAMES": QUICK_FRAMES},
          {"FRAMES": None}, title="Chapter 2: the test benchmark on {TERRAIN}"),
    Entry("ch3_mapping_techniques", "ch3_mapping_techniques.ipynb", {"FRAMES": QUICK_FRAMES},
          {"FRAMES": None}, title="Chapter 3: the four mapping techniques on {TERRAIN}"),
    *(_ch4(terrain) for terrain in TERRAINS),
)

_OURS = "Our maps beside the thesis' rows."
_CLOUD = "Frames and points of our registered cloud beside the thesis'."
KEY_TABLES: tuple[KeyTable, ...] = (
    KeyTable("table_5_7", "Table 5.7: Quadtree sweep", _OURS, rank=70),
    KeyTable("table_5_8", "Table 5.8: Octomap sweep", _OURS, rank=80),
    KeyTable("table_5_9", "Table 5.9: 2D-ALTE sweep", _OURS, rank=90),
    KeyTable("table_5_12", "Table 5.12: 3D-ALTE sweep", _OURS, rank=100),
    KeyTable("table_5_5", "Table 5.5: point cloud for the 3D analysis", _CLOUD, rank=110),
    KeyTable("table_5_6", "Table 5.6: point cloud for the 2D analysis", _CLOUD, rank=120),
)
