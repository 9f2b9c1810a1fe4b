"""The parameter-sensitivity sweep in the report (beyond the thesis)."""

from __future__ import annotations

from alte.lab.entry import QUICK_FRAMES, Entry

__all__ = ["ENTRIES"]

ENTRIES: tuple[Entry, ...] = (
    Entry("ch7_sensitivity", "ch7_sensitivity.ipynb", {"FRAMES": QUICK_FRAMES},
          {"FRAMES": None, "SPEC": "notebooks/sweeps/report.yaml", "SCHEDULER": "local"},
          terrains=("sim_lan_2", "sim_nav_1"),
          title="Beyond the thesis: parameter sensitivity"),
)
