"""Does the answer from the built-in terrains hold on real terrain? Per class of terrain.

The real-terrain evidence (``realterrain_fronts.csv``, :mod:`alte.lab.studies.realterrain`)
has the trade-off table's schema with a ``terrain_class`` (flat open, flat under forest,
slope, steep, built-up) and an ``evidence`` (``flown``: the thesis' missions flown over
the real surface, exact truth; ``points``: the tile's own points mapped, scored on a
held-back 20 %). For each use, class and evidence, :func:`class_checks` reads the order
of the use's two mappers at equal size by the use's truth metric (navigation: also by
completeness, which mean accuracy alone does not see) on that class's terrains
(:func:`~alte.lab.studies.answer.orders.order`) and sets it beside the order on the
simulated built-in terrains: the built-in answer *holds* there when both name the
same leader, *does not hold* when they name different ones, and cannot be told when
either names none.

:func:`sequence_ranks` says whether a real sequence can rank a use's maps at all: the
landing maps of ``balm_seq`` (a street-level walk between walls) lie metres from its
reference cloud, so its landing line is replaced by why.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from alte.lab.studies.answer.choose import GROUPS, Use
from alte.lab.studies.answer.orders import Order, agreement, metric_words, order
from alte.lab.studies.thesis.numbers import TERRAIN_CASE

__all__ = ["CLASS_ORDER", "RANKS_WITHIN", "ClassCheck", "class_checks", "sequence_ranks"]

#: The classes in the order the answer lists them.
CLASS_ORDER = ("flat open", "flat under forest", "slope", "steep", "built-up")
#: A real sequence ranks a use's maps only when its best map is within this many metres of
#: its reference (the use's truth metric; landing: height RMSE).
RANKS_WITHIN = 1.0
_EVIDENCE = {"flown": "flown over the real surface (exact truth)",
             "points": "from the tiles' points (held-back 20 %)"}


@dataclass(frozen=True)
class ClassCheck:
    """One use on one class of real terrain, one kind of evidence, against the built-in."""

    use: Use
    terrain_class: str
    evidence: str
    real: Order
    builtin: Order
    holds: bool | None

    @property
    def metric(self) -> str:
        """The metric both orders read."""
        return self.real.metric

    @property
    def verdict(self) -> str:
        """``holds``, ``does not hold`` or ``cannot tell``."""
        return {True: "holds", False: "does not hold", None: "cannot tell"}[self.holds]

    def text(self) -> str:
        """The check in one sentence."""
        where = ", ".join(self.real.terrains) or "no terrain"
        return (f"{self.terrain_class} ({where}; {_EVIDENCE.get(self.evidence, self.evidence)})"
                f": {metric_words(self.metric)} at equal size {self.real.text(where=False)}"
                f"; built-in: {self.builtin.text(where=False)}: {self.verdict}.")


def class_checks(grid: pd.DataFrame, real: pd.DataFrame | None, use: Use) -> list[ClassCheck]:
    """Every class and evidence of ``real`` for ``use`` beside the simulated built-in
    terrains of ``grid`` (module docstring); [] without real-terrain rows."""
    if real is None or real.empty or "terrain_class" not in real:
        return []
    cases = grid["case"] if "case" in grid else grid["terrain"].map(TERRAIN_CASE)
    simulated = grid[(cases == use.case) & grid["mapper"].isin(use.mappers)
                     & grid["terrain"].astype(str).str.startswith(GROUPS["simulated"])]
    # Navigation is also read by completeness: accuracy alone favours maps covering little.
    metrics = [use.truth, *(["completeness"] if use.second == "completeness" else [])]
    builtin = {m: order(simulated, use, m) for m in metrics}
    mine = real[real["mapper"].isin(use.mappers)]  # the use's maps are of its case
    known = [c for c in CLASS_ORDER if c in set(mine["terrain_class"])]
    out = []
    for cls in [*known, *sorted(set(mine["terrain_class"]) - set(CLASS_ORDER))]:
        for evidence in ("flown", "points"):
            rows = mine[(mine["terrain_class"] == cls) & (mine["evidence"] == evidence)]
            for metric in metrics if not rows.empty else []:
                there = order(rows, use, metric)
                out.append(ClassCheck(use, str(cls), evidence, there, builtin[metric],
                                      agreement(builtin[metric], there)))
    return out


def sequence_ranks(real: pd.DataFrame, use: Use) -> tuple[bool, float]:
    """Whether the real sequence's maps of ``use`` come within :data:`RANKS_WITHIN` of its
    reference (by the use's truth metric), and the best value."""
    values = real.loc[real["mapper"].isin(use.mappers), use.truth].astype(float)
    values = values[np.isfinite(values)]
    if values.empty:
        return False, float("nan")
    best = float(values.max() if use.truth_higher else values.min())
    return (best >= RANKS_WITHIN if use.truth_higher else best <= RANKS_WITHIN), best
