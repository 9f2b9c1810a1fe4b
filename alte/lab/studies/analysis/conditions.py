"""Each "depends" turned into its condition: where a claim holds and where it does not.

A claim that depends has cells (:func:`alte.lab.studies.analysis.evidence.cells_table`: one per
part, terrain and level read) with different outcomes. :func:`condition` reads them
back into one line a reader can act on: per part of the claim (the metric and view it
compares), the terrains where it holds, where it does not, where the interval straddles
the claim's threshold ("undecided") or both maps read the same on every seed ("equal"),
and on a terrain where the outcome changes with
size (or MHD), the levels at which each outcome holds. Terrain sets that are all the
simulated (urban-scale) or all the experimental (lab-scale) terrains of the claim's case
are named as such. A part read from times (a CPU time, the thesis' rule's picks) that
leaves a cell undecided names no terrain or size (:data:`TIMES_UNDECIDED`): which of its
cells a run decides moves with the readings, as its verdict's "uncertainty" says.
"""

from __future__ import annotations

from collections.abc import Sequence

import pandas as pd

from alte.lab.studies.analysis.evidence import Finding
from alte.lab.studies.analysis.tradeoff import METRICS, label, mapper_title
from alte.lab.studies.thesis.claims.types import (
    Agreement,
    AllOf,
    Check,
    Compare,
    Contrast,
    Effect,
    Summary,
    Trend,
)
from alte.lab.studies.thesis.numbers import TERRAIN_CASE

__all__ = ["TIMES_UNDECIDED", "condition", "conditions", "part_label", "terrain_names"]

_WORDS = {"holds": "holds", "does not hold": "does not hold", "inconclusive": "undecided",
          "equal": "equal (no difference)"}
_CASE_WORDS = {"lan": "landing", "nav": "navigation"}
_VIEWS = {"thesis_point": "at the thesis' settings", "rule": "by the thesis' rule",
          "equal_size": "at equal size", "equal_fidelity": "for equal MHD"}


def _pair(check: Check) -> str:
    better, other = getattr(check, "better", None), getattr(check, "other", None)
    if not (isinstance(better, str) and isinstance(other, str)):
        return ""
    return f" ({mapper_title(better)} vs {mapper_title(other)})"


def part_label(check: Check, pair: bool = False) -> str:
    """A short name of what one check compares (its metric and view; ``pair``: and the
    two mappers compared)."""
    if isinstance(check, Compare):
        return f"{label(check.metric, False)} {_VIEWS[check.at]}" + (_pair(check) if pair
                                                                     else "")
    mapper = mapper_title(getattr(check, "mapper", ""))
    if isinstance(check, Trend):
        return f"{label(check.metric, False)} with {label(check.x, False)} ({mapper})"
    if isinstance(check, Agreement):
        return f"{label(check.metric, False)} tracking {label(check.reference, False)} " \
               f"({mapper})"
    if isinstance(check, Summary | Contrast):
        agg = "spread" if check.agg == "cv" else "median"
        return f"{agg} of {label(check.column, False)}" + (
            f" against {check.variant}" if isinstance(check, Contrast) else _pair(check))
    if isinstance(check, Effect):
        return f"effect of {check.param} on {label(check.metric, False)} ({mapper})"
    return type(check).__name__


def terrain_names(terrains: Sequence[str]) -> str:
    """``terrains`` in words; every terrain of one case, or every simulated (or lab)
    terrain of it, named so."""
    chosen = sorted(terrains)
    cases = {TERRAIN_CASE.get(t) for t in chosen}
    if len(cases) == 1 and chosen:
        case = cases.pop()
        if chosen == sorted(t for t, c in TERRAIN_CASE.items() if c == case):
            return f"every {_CASE_WORDS.get(str(case), str(case))} terrain"
        for kind, words in (("sim", "simulated"), ("exp", "lab")):
            every = sorted(t for t, c in TERRAIN_CASE.items() if c == case and
                           t.startswith(kind))
            if chosen == every and len(every) > 1:
                return f"the {words} terrains ({', '.join(chosen)})"
    return ", ".join(chosen)


def _levels(cells: pd.DataFrame, check: Check) -> str:
    """The levels of ``cells`` as a range with its unit (sizes in basis functions, MHD in m)."""
    values = sorted(float(v) for v in cells["level"])
    text = [f"{v:,.0f}" if abs(v) >= 100 else f"{v:.3g}" for v in (values[0], values[-1])]
    span = text[0] if text[0] == text[1] else f"{text[0]}-{text[1]}"
    if isinstance(check, Compare) and check.at == "equal_size":
        return f"{span} {label(check.size, False)}"
    if isinstance(check, Compare) and check.at == "equal_fidelity":
        name, unit = METRICS.get(check.fidelity, (check.fidelity, ""))
        return f"{name} {span} {unit}".rstrip()
    return span


def _where(terrains: list[str], cells: pd.DataFrame, check: Check) -> str:
    here = cells[cells["terrain"].isin(terrains)]
    sized = here["level"].notna().any()
    return terrain_names(terrains) + (f" at {_levels(here, check)}" if sized else "")


def _outcomes(cells: pd.DataFrame) -> pd.DataFrame:
    """The cells with ``equal`` where both mappers read the same on every seed (an
    interval of zero width at zero: nothing to decide, e.g. two perfect precisions)."""
    same = (cells["outcome"] == "inconclusive") & (cells["low"] == 0) & (cells["high"] == 0)
    return cells.assign(outcome=cells["outcome"].where(~same, "equal"))


#: A part read from times with an undecided cell (see :mod:`alte.lab.studies.analysis.evidence`).
TIMES_UNDECIDED = ("undecided within the times' spread (which of its reads a run decides "
                   "moves with the readings)")


def _part_text(cells: pd.DataFrame, check: Check) -> str:
    if ("from_times" in cells and cells["from_times"].fillna(False).astype(bool).any()
            and (cells["outcome"] == "inconclusive").any()):
        return TIMES_UNDECIDED
    cells = _outcomes(cells) if {"low", "high"} <= set(cells.columns) else cells
    whole: dict[str, list[str]] = {}
    mixed = []
    for terrain, here in cells.groupby("terrain", sort=True):
        outcomes = list(dict.fromkeys(here.sort_values("level")["outcome"]))
        if len(outcomes) == 1:
            whole.setdefault(outcomes[0], []).append(str(terrain))
            continue
        at = [f"{_WORDS.get(o, o)} at {_levels(here[here['outcome'] == o], check)}"
              for o in outcomes]
        mixed.append(f"on {terrain} {', '.join(at)}")
    parts = [f"{_WORDS.get(o, o)} on {_where(whole[o], cells, check)}"
             for o in ("holds", "does not hold", "inconclusive", "equal") if o in whole]
    return "; ".join(parts + mixed)


def condition(finding: Finding) -> str:
    """One line: where ``finding``'s claim holds and where not (empty unless it depends);
    the parts of a claim making several comparisons are separated by " | "."""
    if finding.verdict != "depends":
        return ""
    check = finding.claim.check
    parts = check.parts if isinstance(check, AllOf) else (check,)
    pairs = len({(getattr(p, "better", ""), getattr(p, "other", "")) for p in parts}) > 1
    cells = finding.cells
    lines = []
    for i, part in enumerate(parts, 1):
        mine = cells[cells["part"] == i] if len(parts) > 1 else cells
        text = _part_text(mine, part) if not mine.empty else "not measured"
        lines.append(f"{part_label(part, pairs)}: {text}" if len(parts) > 1 else text)
    return " | ".join(lines)


def conditions(findings: Sequence[Finding]) -> list[str]:
    """:func:`condition` of every finding, in order."""
    return [condition(f) for f in findings]
