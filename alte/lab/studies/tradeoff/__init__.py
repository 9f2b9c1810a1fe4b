"""The trade-off grid of chapter 5: every mapper's settings on every terrain and seed.

- :mod:`~alte.lab.studies.tradeoff.grid`: the grid run once, as trade-off tables and ablations.
- :mod:`~alte.lab.studies.tradeoff.figures`: its fronts (size, time, fidelity) and the
  equal-size / equal-fidelity reads.
- :mod:`~alte.lab.studies.tradeoff.ablation`: what moves the verdicts, drawn.
"""

__all__: list[str] = []
