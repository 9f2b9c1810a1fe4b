"""Chapter 6 in the report: the real sequences, their ground and their poses."""

from __future__ import annotations

from alte.lab.entry import QUICK_FRAMES, Entry

__all__ = ["ENTRIES", "POSE_SEQUENCES"]

#: The real sequences of table 6.4 (``alte.lab.studies.poses.benchmark.REAL_SEQUENCES``,
#: named here so that reading the plan does not load the pose benchmark).
POSE_SEQUENCES = ("balm_seq", "balm_seq2")

ENTRIES: tuple[Entry, ...] = (
    Entry("ch6_real_data", "ch6_real_data.ipynb",
          {"FRAMES": QUICK_FRAMES, "FRONT_FRAMES": 10, "FRONT_GRID": None,
           "POSE_SEQUENCES": list(POSE_SEQUENCES)},
          {"FRAMES": None, "FRONT_FRAMES": 20, "FRONT_GRID": None,
           "POSE_SEQUENCES": list(POSE_SEQUENCES)},
          title="Chapter 6: real data"),
)
