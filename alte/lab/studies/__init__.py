"""The studies: the thesis' experiments and ours, one folder per study.

- :mod:`~alte.lab.studies.thesis`: what the thesis says, as data (its tables and
  parameters, its comparative claims); nothing here measures.
- :mod:`~alte.lab.studies.analysis`: trade-off tables, per-seed measures of the claims'
  checks, comparisons, verdicts with their evidence and uncertainty, the thesis' tables
  rebuilt from measurements.
- ``experiments`` and ``missions``: the measurements the chapters share.
- One folder per study, each holding its experiment, its ``figures`` and its ``report``
  entry (notebook run, chapter title, key tables): ``tradeoff`` (the grid and its
  ablations), ``sensor``, ``poses``, ``landing``, ``planning``, ``realdata``,
  ``realterrain``, ``obstacles``, ``sweep``; ``answer`` (the report's answer).
"""
