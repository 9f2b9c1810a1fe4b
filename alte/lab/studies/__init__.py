"""Studies on top of the pipeline, in three layers.

- :mod:`~alte.lab.studies.thesis`: what the thesis says, as data (its tables and parameters, its
  comparative claims); nothing here measures.
- :mod:`~alte.lab.studies.analysis`: trade-off tables, per-seed measures of the claims' checks,
  comparisons, verdicts with their evidence and uncertainty, the thesis' tables rebuilt from
  measurements.
- The chapters' experiments (``experiments``, ``grid``, ``missions``, ``sensor``, ``odometry``)
  and the applications (``landing``, ``planning``, ``realdata``, ``obstacles``, ``sweep``,
  ``answer``), each in its own module or package.
"""
