"""The front page's bottom line as text: read from the run's tables, never typed in.

:func:`answer_view` reads ``tradeoff.csv`` (the grid, obstacle columns included) and,
when chapter 6 ran, ``realdata_fronts.csv`` and ``realterrain_fronts.csv`` from a run's
tables folder, computes the
:func:`~alte.lab.studies.answer.bottom_line` and turns it into rows of text the template
shows under ``id="answer"``: per use a summary, one row per terrain group and budget
(the pick with its figures and intervals, the other mapper's best, the pick the thesis'
MHD would make), the orders at equal size, where MHD and the truth disagree, whether
the real sequence agrees (or why it cannot rank the use's maps), and per class of real
terrain whether the built-in answer holds.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

from alte.lab.studies.analysis.tradeoff import mapper_title
from alte.lab.studies.answer import Choice, UseAnswer, bottom_line, interval_text, pick_text
from alte.lab.studies.answer.classes import ClassCheck
from alte.lab.studies.answer.orders import metric_words

__all__ = ["REAL_CSV", "TERRAIN_CSV", "TRADEOFF_CSV", "AnswerView", "ChoiceRow", "ClassRow",
           "UseView", "answer_view"]

#: The tables the bottom line is read from (in the run's ``tables`` folder).
TRADEOFF_CSV = "tradeoff.csv"
REAL_CSV = "realdata_fronts.csv"
TERRAIN_CSV = "realterrain_fronts.csv"


@dataclass(frozen=True)
class ChoiceRow:
    """One budget on one terrain group: the pick and what it is measured against."""

    group: str
    budget: str
    choose: str
    mapper: str
    figures: str
    rival: str
    mhd: str


@dataclass(frozen=True)
class ClassRow:
    """One class of real terrain and one kind of evidence: the order there and the
    built-in one, and whether the built-in answer holds."""

    terrain_class: str
    terrains: str
    evidence: str
    real: str
    verdict: str
    css: str


@dataclass(frozen=True)
class UseView:
    """A use's part of the bottom line."""

    title: str
    summary: str
    disagreement: str
    rows: list[ChoiceRow]
    orders: list[str]
    real: list[str]
    real_why: str = ""
    classes: list[ClassRow] = field(default_factory=list)
    builtin: str = ""
    duels: list[str] = field(default_factory=list)
    calibration: list[str] = field(default_factory=list)


@dataclass(frozen=True)
class AnswerView:
    """The whole bottom line: the uses, then a note on the real data."""

    uses: list[UseView]
    real_note: str


def _rival(choice: Choice) -> str:
    if choice.rival is None:
        other = [m for m in choice.use.mappers if choice.best and m != choice.best.mapper]
        names = ", ".join(mapper_title(m) for m in other)
        return f"no {names} map fits" if names else ""
    if choice.budget.kind == "need":
        return (f"{choice.rival.name} at the least: {choice.rival.setting}, "
                f"{choice.rival.size:,.0f} basis functions")
    sure = ("the difference lies beyond its interval" if choice.decided
            else "within the interval of the difference")
    truth = interval_text(choice.rival.truth, choice.use.truth)
    return (f"{choice.rival.name} at best: {choice.rival.setting}, "
            f"{metric_words(choice.use.truth)} {truth} ({sure})")


def _mhd(choice: Choice) -> str:
    if choice.by_mhd is None or choice.best is None:
        return ""
    if (choice.by_mhd.mapper, choice.by_mhd.setting) == (choice.best.mapper,
                                                         choice.best.setting):
        return "the same map"
    return f"{choice.by_mhd.name} {choice.by_mhd.setting}"


def _row(choice: Choice) -> ChoiceRow:
    group = f"{choice.group} terrains ({', '.join(choice.terrains)})"
    if choice.best is None:
        return ChoiceRow(group, choice.budget.text(choice.use), "no map of the grid fits", "",
                         "", "", "")
    return ChoiceRow(group, choice.budget.text(choice.use),
                     f"{choice.best.name} {choice.best.setting}", choice.best.mapper,
                     pick_text(choice.best, choice.use), _rival(choice), _mhd(choice))


_EVIDENCE = {"flown": "flown (exact truth)", "points": "tile's points (held-back 20 %)"}
_CSS = {"holds": "holds", "does not hold": "fails", "cannot tell": "depends"}


def _class_row(check: ClassCheck) -> ClassRow:
    return ClassRow(check.terrain_class, ", ".join(check.real.terrains),
                    _EVIDENCE.get(check.evidence, check.evidence),
                    f"{metric_words(check.metric)}: {check.real.text(where=False)} (built-in: "
                    f"{check.builtin.text(where=False)})", check.verdict, _CSS[check.verdict])


def _use(found: UseAnswer, sequence: str) -> UseView:
    names = " or ".join(mapper_title(m) for m in found.use.mappers)
    title = (f"{found.use.name.capitalize()}: {names}, ranked by "
             f"{metric_words(found.use.truth)}")
    orders = [f"{metric_words(o.metric)}: {o.text()}" for o in found.orders]
    builtin = "; ".join(dict.fromkeys(
        f"{metric_words(c.metric)}: {c.builtin.text(where=False)}" for c in found.classes))
    return UseView(title, found.summary, found.disagreement, [_row(c) for c in found.choices],
                   orders, [check.text(sequence) for check in found.real], found.real_why,
                   [_class_row(c) for c in found.classes], builtin,
                   [d.text() for d in found.duels], [c.text() for c in found.calibration])


def _read(path: Path) -> pd.DataFrame | None:
    try:
        return pd.read_csv(path) if path.is_file() else None
    except (OSError, ValueError, pd.errors.EmptyDataError):
        return None


def answer_view(tables_dir: str | Path) -> AnswerView | None:
    """The bottom line of the run whose tables are in ``tables_dir`` (None without a
    trade-off grid)."""
    folder = Path(tables_dir)
    grid = _read(folder / TRADEOFF_CSV)
    if grid is None or grid.empty:
        return None
    found = bottom_line(grid, _read(folder / REAL_CSV), _read(folder / TERRAIN_CSV))
    return AnswerView([_use(u, found.sequence) for u in found.uses], found.real_note)
