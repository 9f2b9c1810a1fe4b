"""The path-planning study in the report (beyond the thesis)."""

from __future__ import annotations

from alte.lab.entry import QUICK_FRAMES, Entry

__all__ = ["ENTRIES"]

ENTRIES: tuple[Entry, ...] = (
    Entry("ch7_planning", "ch7_planning.ipynb", {"FRAMES": QUICK_FRAMES}, {"FRAMES": None},
          terrains=("sim_nav_1", "sim_nav_2", "exp_nav_1", "exp_nav_2"),
          title="Beyond the thesis: path planning"),
)
