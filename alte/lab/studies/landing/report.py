"""The landing-site study in the report (beyond the thesis)."""

from __future__ import annotations

from alte.lab.entry import QUICK_FRAMES, Entry

__all__ = ["ENTRIES"]

ENTRIES: tuple[Entry, ...] = (
    Entry("ch7_landing", "ch7_landing.ipynb", {"FRAMES": QUICK_FRAMES}, {"FRAMES": None},
          terrains=("sim_lan_1", "sim_lan_2", "exp_lan_1", "exp_lan_2"),
          title="Beyond the thesis: landing-site selection"),
)
