"""Mappers beyond the thesis' two in the answer: where each beats or loses, and how honest
its claimed height uncertainty is.

A *challenger* of a use is a mapper of the grid with the use's dimension (the ``dims``
column the sweep writes: 2 for landing, 3 for navigation) that is not one of the thesis'
pair, e.g. a plugin such as the elevation map. It enters the use's candidates (a budget
may pick it); here it is also read against each of the thesis' two, terrain by terrain,
at equal size by the use's truth (:func:`~alte.lab.studies.answer.orders.order`: the fronts
read at three sizes, a read going to a mapper when the interval of the paired
difference over seeds lies on its side): :class:`Duel`; and on the real-terrain evidence
(``realterrain_fronts.csv``) class by class of terrain and kind of evidence
(:func:`class_duels`).

:class:`Calibration` summarises, per mapper whose cells claim a height variance, the
share of the probed area whose true height lies within two claimed sigmas
(``within_2sigma`` of :mod:`alte.metrics.truth`; 0.954 for a calibrated Gaussian), per
terrain group.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import cast

import numpy as np
import pandas as pd

from alte.lab.studies.analysis.tradeoff import mapper_title
from alte.lab.studies.answer.choose import GROUPS, Use
from alte.lab.studies.answer.classes import CLASS_ORDER
from alte.lab.studies.answer.orders import metric_words, order

__all__ = ["CALIBRATED", "Calibration", "Duel", "calibrations", "challengers", "class_duels",
           "duels"]

#: The share within two sigma of a calibrated Gaussian sigma.
CALIBRATED = 0.954


def challengers(table: pd.DataFrame, use: Use) -> tuple[str, ...]:
    """The grid's mappers of ``use``'s dimension beyond its thesis' pair (sorted)."""
    if "dims" not in table or use.dims is None:
        return ()
    mine = table[(table["dims"] == use.dims) & ~table["mapper"].isin(use.mappers)]
    return tuple(sorted(set(mine["mapper"].astype(str))))


@dataclass(frozen=True)
class Duel:
    """A challenger against one of the thesis' mappers, terrain by terrain: per terrain the
    reads at equal size that went to each and how many stayed within their interval."""

    use: Use
    challenger: str
    rival: str
    terrains: tuple[tuple[str, int, int, int], ...]  # (terrain, challenger's, rival's, reads)
    where: str = ""  # "on real terrain": ``terrains`` are classes of terrain

    def text(self) -> str:
        """e.g. ``"Elevation map against Quadtree: leads on sim_lan_1 (3 of 3 reads), loses on
        exp_lan_1 (2 of 3), undecided on exp_lan_2 (3 reads)"``."""
        parts: dict[str, list[str]] = {"leads": [], "loses": [], "undecided": []}
        for terrain, ours, theirs, reads in self.terrains:
            if ours > theirs:
                parts["leads"].append(f"{terrain} ({ours} of {reads} reads)")
            elif theirs > ours:
                parts["loses"].append(f"{terrain} ({theirs} of {reads})")
            else:
                parts["undecided"].append(f"{terrain} ({reads} reads)")
        said = [f"{verb} on {', '.join(where)}" for verb, where in parts.items() if where]
        head = (f"{mapper_title(self.challenger)} against {mapper_title(self.rival)}"
                f"{' ' + self.where if self.where else ''}, "
                f"{metric_words(self.use.truth)} at equal size")
        return f"{head}: {'; '.join(said)}" if said else f"{head}: no common size to compare"


def duels(table: pd.DataFrame, use: Use) -> list[Duel]:
    """Every challenger of ``use`` against each of its thesis' two, terrain by terrain."""
    out = []
    for challenger in challengers(table, use):
        for rival in use.mappers[:2]:
            pair = replace(use, mappers=(challenger, rival))
            rows = []
            for terrain in sorted(set(table["terrain"].astype(str))):
                found = order(table[table["terrain"] == terrain], pair, use.truth)
                if found.reads:
                    rows.append((terrain, found.leads.get(challenger, 0),
                                 found.leads.get(rival, 0), found.reads))
            out.append(Duel(use, challenger, rival, tuple(rows)))
    return out


_EVIDENCE = {"flown": "flown", "points": "its points"}


def class_duels(real: pd.DataFrame | None, use: Use) -> list[Duel]:
    """Every challenger of ``use`` in the real-terrain evidence against each of its thesis'
    two, class by class of terrain and kind of evidence ("flat open, flown")."""
    if real is None or real.empty or "terrain_class" not in real:
        return []
    mine = real[real["case"] == use.case] if "case" in real else real
    extra = sorted(set(mine["mapper"].astype(str)) - set(use.mappers))
    classes = [c for c in CLASS_ORDER if c in set(mine["terrain_class"])]
    classes += sorted(set(mine["terrain_class"].astype(str)) - set(CLASS_ORDER))
    out = []
    for challenger in extra:
        for rival in use.mappers[:2]:
            pair = replace(use, mappers=(challenger, rival))
            rows = []
            for cls in classes:
                for evidence in ("flown", "points"):
                    part = mine[(mine["terrain_class"] == cls) & (mine["evidence"] == evidence)]
                    found = order(part, pair, use.truth) if not part.empty else None
                    if found is not None and found.reads:
                        rows.append((f"{cls} ({_EVIDENCE.get(evidence, evidence)})",
                                     found.leads.get(challenger, 0),
                                     found.leads.get(rival, 0), found.reads))
            if rows:
                out.append(Duel(use, challenger, rival, tuple(rows), "on real terrain"))
    return out


@dataclass(frozen=True)
class Calibration:
    """How often a mapper's claimed height sigma covers the truth, per terrain group: the
    median ``within_2sigma`` over its settings and seeds with its range, and the median
    claimed sigma (m)."""

    mapper: str
    group: str
    terrains: tuple[str, ...]
    median: float
    low: float
    high: float
    sigma_m: float
    maps: int

    def text(self) -> str:
        """The calibration in one sentence."""
        verdict = ("calibrated" if abs(self.median - CALIBRATED) <= 0.02
                   else "over-confident" if self.median < CALIBRATED else "cautious")
        return (f"{mapper_title(self.mapper)} on the {self.group} terrains "
                f"({', '.join(self.terrains)}): the true height lies within 2 claimed sigma "
                f"on {100 * self.median:.1f} % of the mapped area (median of {self.maps} maps, "
                f"{100 * self.low:.1f}-{100 * self.high:.1f} %; median sigma "
                f"{1000 * self.sigma_m:.1f} mm): {verdict} (a calibrated sigma: "
                f"{100 * CALIBRATED:.1f} %)")


def calibrations(table: pd.DataFrame, real: pd.DataFrame | None = None) -> list[Calibration]:
    """Per mapper whose maps claim a height variance and terrain group, a
    :class:`Calibration` (none when the table has no ``within_2sigma``); with ``real``
    (the real-terrain evidence), per class of real terrain too (its flown maps, which
    have the exact truth)."""
    out = []
    if "within_2sigma" in table:
        rows = table[np.isfinite(table["within_2sigma"].astype(float))]
        for mapper in sorted(set(rows["mapper"].astype(str))):
            for group, prefix in GROUPS.items():
                mine = rows[(rows["mapper"] == mapper)
                            & rows["terrain"].astype(str).str.startswith(prefix)]
                if not mine.empty:
                    out.append(_calibration(mapper, group, mine))
    if real is not None and "within_2sigma" in real and "terrain_class" in real:
        rows = real[np.isfinite(real["within_2sigma"].astype(float))]
        for key, part in rows.groupby(["mapper", "terrain_class"], sort=True):
            name, cls = (str(k) for k in cast("tuple[object, object]", key))
            out.append(_calibration(name, f"real {cls}", part))
    return out


def _calibration(mapper: str, group: str, mine: pd.DataFrame) -> Calibration:
    """The :class:`Calibration` of one mapper's rows on one terrain group."""
    share = mine["within_2sigma"].astype(float)
    return Calibration(mapper, group, tuple(sorted(set(mine["terrain"].astype(str)))),
                       float(share.median()), float(share.min()), float(share.max()),
                       float(mine["sigma_mean_m"].astype(float).median()), len(mine))
