"""The report's bottom line, generated from its tables: which map to build, and how sure.

:func:`bottom_line` takes the trade-off grid (``tradeoff.csv``, obstacle columns
included) and, when chapter 6 ran, the real sequence's fronts (``realdata_fronts.csv``)
and the real-terrain evidence (``realterrain_fronts.csv``), and returns a
:class:`BottomLine`: per use (:data:`~alte.lab.studies.answer.choose.USES`) the choice under
every budget on each terrain group (:mod:`~alte.lab.studies.answer.choose`), a one-sentence
summary, the orders at equal size by the thesis' MHD and by the truth
(:mod:`~alte.lab.studies.answer.orders`) with whether they rank the maps differently, for
each of those comparisons whether the real sequence agrees with the simulated terrains
(or why it cannot rank that use's maps), per class of real terrain whether the
built-in answer holds there (:mod:`~alte.lab.studies.answer.classes`), and, with further
mappers of the use's dimension in the grid (plugins), where each beats or loses against
the thesis' two, terrain by terrain, and how well the height sigma a map claims covers
the truth (:mod:`~alte.lab.studies.answer.challengers`). Every sentence is built from these
numbers; nothing is typed in.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass, field, replace

import numpy as np
import pandas as pd

from alte.lab.studies.analysis.tradeoff import METRICS, mapper_title
from alte.lab.studies.analysis.uncertainty import Interval
from alte.lab.studies.answer.challengers import (
    Calibration,
    Duel,
    calibrations,
    challengers,
    class_duels,
    duels,
)
from alte.lab.studies.answer.choose import (
    GROUPS,
    USES,
    Choice,
    Pick,
    Use,
    budgets,
    candidates,
    choose,
)
from alte.lab.studies.answer.classes import RANKS_WITHIN, ClassCheck, class_checks, sequence_ranks
from alte.lab.studies.answer.orders import Order, agreement, metric_words, order
from alte.lab.studies.thesis.numbers import TERRAIN_CASE

__all__ = ["BottomLine", "RealCheck", "UseAnswer", "bottom_line", "interval_text", "pick_text"]


@dataclass(frozen=True)
class RealCheck:
    """One comparison on the simulated terrains and on the real sequence."""

    metric: str
    simulated: Order
    real: Order
    agrees: bool | None

    def text(self, sequence: str) -> str:
        """The comparison in one sentence."""
        verdict = {True: "agrees", False: "disagrees", None: "cannot tell"}[self.agrees]
        return (f"{metric_words(self.metric)} at equal size: simulated terrains "
                f"{self.simulated.text(where=False)}; {sequence} {self.real.text(where=False)}: "
                f"{verdict}.")


@dataclass(frozen=True)
class UseAnswer:
    """A use's choices, summary, orders at equal size and real-data checks."""

    use: Use
    choices: list[Choice]
    summary: str
    orders: list[Order]
    disagreement: str
    real: list[RealCheck] = field(default_factory=list)
    real_why: str = ""
    classes: list[ClassCheck] = field(default_factory=list)
    duels: list[Duel] = field(default_factory=list)
    calibration: list[Calibration] = field(default_factory=list)


@dataclass(frozen=True)
class BottomLine:
    """Everything the front page's answer shows (module docstring)."""

    uses: list[UseAnswer]
    sequence: str = ""
    real_note: str = ""


def _number(value: float) -> str:
    if not np.isfinite(value):
        return "n/a"
    return f"{value:,.0f}" if abs(value) >= 1000 else f"{value:.3g}"


def interval_text(interval: Interval, metric: str) -> str:
    """``"0.21 m [0.20, 0.22]"``: the mean with its interval and unit."""
    unit = METRICS.get(metric, ("", ""))[1]
    unit = f" {unit}" if unit else ""
    if interval.seeds < 2:
        return f"{_number(interval.estimate)}{unit}"
    return (f"{_number(interval.estimate)}{unit} [{_number(interval.low)}, "
            f"{_number(interval.high)}]")


def pick_text(pick: Pick, use: Use) -> str:
    """A pick's figures: truth, second metric, MHD with intervals, size and time."""
    time = f", {pick.ms:.2g} ms per scan" if np.isfinite(pick.ms) else ""
    return (f"{metric_words(use.truth)} {interval_text(pick.truth, use.truth)}, "
            f"{metric_words(use.second)} {interval_text(pick.second, use.second)}, "
            f"MHD {interval_text(pick.mhd, 'mhd_m')}; {pick.size:,.0f} basis functions{time}")


def _summary(use: Use, choices: Sequence[Choice]) -> str:
    picked = [c for c in choices if c.best is not None]
    if not picked:
        return f"No {use.name} map of the grid meets a budget."
    wins = Counter(c.best.mapper for c in picked if c.best is not None)
    sure = Counter(c.best.mapper for c in picked if c.best is not None and c.decided)
    parts = [f"{mapper_title(m)} under {n} of {len(picked)} ({sure[m]} beyond the "
             f"interval of the difference)" for m, n in wins.most_common()]
    absent = [mapper_title(m) for m in use.mappers if m not in wins]
    mhd = [c for c in picked if c.by_mhd is not None and c.best is not None
           and c.by_mhd.mapper != c.best.mapper]
    text = (f"For {use.name}, ranked by {metric_words(use.truth)}: " + "; ".join(parts)
            + (f"; {', '.join(absent)} under none" if absent else "") + ".")
    if mhd:
        text += (f" The thesis' MHD would pick the other mapper under {len(mhd)} of "
                 f"{len(picked)} budgets.")
    return text


def _disagreement(use: Use, orders: Sequence[Order]) -> str:
    mhd = next((o for o in orders if o.metric == "mhd_m"), None)
    differs = [o for o in orders if mhd is not None and o.metric != "mhd_m"
               and agreement(mhd, o) is False]
    if mhd is None or not differs:
        return ""
    names = ", ".join(metric_words(o.metric) for o in differs)
    return (f"The thesis' MHD and the truth rank the {use.name} maps differently: at equal "
            f"size MHD favours {mapper_title(mhd.leader)}, {names} "
            f"{'favour' if len(differs) > 1 else 'favours'} "
            f"{mapper_title(differs[0].leader)}.")


def _metrics(use: Use, table: pd.DataFrame) -> list[str]:
    extra = ["obstacle_precision"] if use.case == "lan" else []
    wanted = ["mhd_m", use.truth, use.second, *extra]
    return [m for m in dict.fromkeys(wanted) if m in table and table[m].notna().any()]


def _real_checks(real: pd.DataFrame | None, use: Use, orders: Sequence[Order]
                 ) -> tuple[list[RealCheck], str]:
    """The real sequence's checks, or why it cannot rank this use's maps."""
    if real is None or real.empty:
        return [], ""
    ranks, best = sequence_ranks(real, use)
    if not ranks:
        name = str(real["terrain"].iloc[0])
        return [], (f"{name} cannot rank {use.name} maps: its best map is "
                    f"{best:.2f} m ({metric_words(use.truth)}) from its reference cloud, "
                    f"beyond the {RANKS_WITHIN:g} m within which its maps can be told apart; "
                    "the real terrains below rank them instead.")
    checks = []
    for simulated in orders:
        if simulated.metric in real and real[simulated.metric].notna().any():
            there = order(real, use, simulated.metric)
            checks.append(RealCheck(simulated.metric, simulated, there,
                                    agreement(simulated, there)))
    return checks, ""


def _use_answer(grid: pd.DataFrame, real: pd.DataFrame | None, use: Use,
                terrain: pd.DataFrame | None = None,
                cover: Sequence[float] = ()) -> UseAnswer:
    cases = grid["case"] if "case" in grid else grid["terrain"].map(TERRAIN_CASE)
    mine = grid[cases == use.case]
    wide = replace(use, mappers=use.mappers + challengers(mine, use))
    choices = []
    for group, prefix in GROUPS.items():
        terrains = sorted({t for t in mine["terrain"].astype(str) if t.startswith(prefix)})
        if not terrains:
            continue
        pool = candidates(mine, wide, group)
        choices += [choose(pool, wide, group, terrains, b)
                    for b in budgets(pool, wide, cover=cover)]
    orders = [order(mine, use, m) for m in _metrics(use, mine)]
    checks, why = _real_checks(real, use, orders)
    mapped = mine[mine["dims"] == use.dims] if "dims" in mine and use.dims else mine
    return UseAnswer(use, choices, _summary(wide, choices), orders,
                     _disagreement(use, orders), checks, why,
                     class_checks(grid, terrain, use),
                     duels(mine, use) + class_duels(terrain, use),
                     calibrations(mapped, terrain[terrain["case"] == use.case]
                                  if terrain is not None and "case" in terrain else None))


def bottom_line(grid: pd.DataFrame, real: pd.DataFrame | None = None,
                terrain: pd.DataFrame | None = None,
                cover: Sequence[float] = ()) -> BottomLine:
    """The bottom line of a run from its trade-off grid, the real sequence's fronts and the
    real-terrain evidence (module docstring); ``cover``: completeness needs the reader
    states for navigation (besides those read off the candidates)."""
    answers = [_use_answer(grid, real, use, terrain, cover) for use in USES]
    sequence = ""
    note = "No real sequence in this run (chapter 6 skipped, or realdata_fronts.csv absent)."
    if real is not None and not real.empty:
        sequence = str(real["terrain"].iloc[0])
        note = (f"Real data: {sequence}, {int(real['frames'].iloc[0])} real scans mapped "
                f"with their reference poses, measured against the reference cloud of "
                f"every scan (one recording: no interval).")
    return BottomLine(answers, sequence, note)
