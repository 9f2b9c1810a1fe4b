"""Which of a use's two mappers leads at equal size, by one metric, over a set of terrains.

The fronts of both mappers are read at three sizes inside the range both cover, per
terrain (:func:`alte.lab.studies.analysis.tradeoff.equal_size`); at each (terrain, size) read the
paired difference over seeds gets a 95 % bootstrap interval, and the read *goes to* a
mapper when the interval lies wholly on its side (a single recording has no interval:
its read goes to whichever is better). :func:`order` counts the reads; :func:`agreement`
sets two orders side by side: the thesis' MHD against the truth on the same terrains
(where they rank the maps differently), or the simulated terrains against a real
sequence (whether the real data agree).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import pandas as pd

from alte.lab.studies.analysis.tradeoff import equal_size, label, mapper_title, prepare
from alte.lab.studies.analysis.uncertainty import bootstrap_ci
from alte.lab.studies.answer.choose import Use

__all__ = ["HIGHER", "Order", "agreement", "metric_words", "order"]

#: Metrics where higher is better (the rest: lower is better).
HIGHER = frozenset({"completeness", "obstacle_recall", "obstacle_precision"})


@dataclass(frozen=True)
class Order:
    """The reads of one metric at equal size on ``terrains``: how many went to each mapper
    (``leads``), how many stayed within their interval, and where each mapper led."""

    use: Use
    metric: str
    terrains: tuple[str, ...]
    reads: int
    leads: dict[str, int] = field(default_factory=dict)
    where: dict[str, tuple[str, ...]] = field(default_factory=dict)

    @property
    def undecided(self) -> int:
        """Reads whose interval straddles zero."""
        return self.reads - sum(self.leads.values())

    @property
    def leader(self) -> str:
        """The mapper most reads went to ("" when none did, or both equally)."""
        counts = sorted(self.leads.items(), key=lambda kv: -kv[1])
        if not counts or counts[0][1] == 0 or (len(counts) > 1 and counts[0][1] == counts[1][1]):
            return ""
        return counts[0][0]

    def text(self, where: bool = True) -> str:
        """e.g. ``"2D-ALTE on 9 of 12 reads (sim_lan_1, sim_lan_2), Quadtree on 1"``
        (``where=False``: without the terrains)."""
        if not self.reads:
            return "no read"
        parts: list[str] = []
        for mapper, n in sorted(self.leads.items(), key=lambda kv: -kv[1]):
            if n:
                places = ", ".join(self.where.get(mapper, ())) if where else ""
                parts.append(f"{mapper_title(mapper)} on {n} of {self.reads} "
                             f"read{'s' if self.reads != 1 else ''}"
                             + (f" ({places})" if places and not parts else ""))
        if self.undecided:
            parts.append(f"{self.undecided} within their interval")
        return ", ".join(parts) or "no read decided"


def _reads(table: pd.DataFrame, use: Use, metric: str) -> pd.DataFrame:
    """(terrain, level, seed, difference first minus second mapper) at equal size."""
    pair = use.mappers[:2]
    rows = table[table["mapper"].isin(pair)]
    if metric not in rows or rows[metric].isna().all() or set(pair) - set(rows["mapper"]):
        return pd.DataFrame(columns=["terrain", "level", "seed", "diff"])
    reads = equal_size(prepare(rows), pair, metric, higher_is_better=metric in HIGHER)
    wide = reads.pivot_table(index=["terrain", "level", "seed"], columns="mapper",
                             values="value").dropna()
    if wide.empty or set(pair) - set(wide.columns):
        return pd.DataFrame(columns=["terrain", "level", "seed", "diff"])
    first, second = use.mappers[:2]
    return (wide[first] - wide[second]).rename("diff").reset_index()


def order(table: pd.DataFrame, use: Use, metric: str) -> Order:
    """The equal-size reads of ``metric`` for ``use``'s mappers on ``table``'s terrains."""
    diffs = _reads(table, use, metric)
    sign = 1.0 if metric in HIGHER else -1.0  # a positive signed difference: first leads
    pair = use.mappers[:2]
    leads = dict.fromkeys(pair, 0)
    where: dict[str, list[str]] = {m: [] for m in pair}
    reads = 0
    for (terrain, _), group in diffs.groupby(["terrain", "level"], sort=True):
        ci = bootstrap_ci(sign * group["diff"].to_numpy(float))
        if ci.seeds == 0:
            continue
        reads += 1
        low, high = (ci.estimate, ci.estimate) if ci.seeds == 1 else (ci.low, ci.high)
        winner = pair[0] if low > 0 else pair[1] if high < 0 else ""
        if winner:
            leads[winner] += 1
            where[winner].append(str(terrain))
    terrains = tuple(sorted(set(diffs["terrain"].astype(str))))
    return Order(use, metric, terrains, reads, leads,
                 {m: tuple(dict.fromkeys(w)) for m, w in where.items()})


def agreement(first: Order, second: Order) -> bool | None:
    """Whether two orders name the same leader (None when either names none)."""
    if not first.leader or not second.leader:
        return None
    return first.leader == second.leader


def metric_words(metric: str) -> str:
    """A metric's name for sentences (``"MHD"``, ``"height RMSE"``)."""
    return label(metric, False)
