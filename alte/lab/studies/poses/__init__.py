"""Poses on real sequences (chapter 6's table 6.4 and the pose defaults).

- :mod:`~alte.lab.studies.poses.benchmark`: every pose source of a recording scored
  against its reference poses.
- :mod:`~alte.lab.studies.poses.defaults`: the pose defaults chosen on one sequence and
  checked on another (``bench/pose_defaults.py`` runs it).
"""

__all__: list[str] = []
