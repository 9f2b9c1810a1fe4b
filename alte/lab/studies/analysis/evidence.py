"""Verdicts on the thesis' claims from a trade-off table, with their evidence.

Each check of a claim is measured per terrain, level and seed
(:mod:`alte.lab.studies.analysis.measures`); per (terrain, level) cell the mean over seeds gets a
percentile-bootstrap interval (:mod:`alte.lab.studies.analysis.uncertainty`). A cell *holds* when
its interval lies wholly on the claim's side of the threshold, *does not hold* when it
lies wholly on the other side, and is *inconclusive* otherwise (or with fewer than
``min_seeds`` seeds). A check holds (does not hold) when every cell does; otherwise
it *depends*, on the ``terrain``, the ``size`` or ``fidelity`` level, or on
``uncertainty`` (intervals straddle the threshold). A conjunction (:class:`AllOf`)
holds when all parts hold, does not hold when all parts do not, and otherwise depends
on what tells the parts apart (``view``, ``metric``, ``mapper``, ``case``).
Claims no map metric decides are ``not measurable``; checks the table cannot feed
(missing rows, columns or settings) give ``no data``.

Time (:mod:`alte.lab.studies.analysis.measures`): a within-mapper check on the elapsed time is
judged
on the mapper's machine-independent cost and cross-checked on its CPU time; a
comparison of two mappers' times is judged on their CPU times, each seed's value known
only within the times' spreads, so its interval runs from the bootstrap low of the
seeds' lower bounds to the bootstrap high of their upper bounds (as for a tie of the
thesis' rule). A verdict thus never rests on a difference smaller than a time's spread.
``time_check`` says how (``cost``, or ``CPU time``); for the cost, the evidence ends with
the same statistic on the CPU time and the cells where it decides the other way. A check
whose values are read from times (a CPU time, the rule's picks) and leaves a cell
undecided depends on ``uncertainty`` alone: which of its cells a run decides moves with
the readings, so they name no terrain or size.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, fields

import numpy as np
import pandas as pd

from alte.lab.studies.analysis.measures import CheckValues, NoDataError, measure_check
from alte.lab.studies.analysis.tradeoff import mapper_title, prepare
from alte.lab.studies.analysis.uncertainty import (
    CONFIDENCE,
    Interval,
    bootstrap_bounds,
    bootstrap_ci,
)
from alte.lab.studies.analysis.wording import (
    check_text,
    time_check_text,
)
from alte.lab.studies.thesis.claims.types import (
    AllOf,
    Check,
    Claim,
    Contrast,
    NotMeasurable,
    Property,
    renamed,
)
from alte.params import Record, param

__all__ = ["CELL_COLUMNS", "CLAIM_COLUMNS", "VERDICTS", "EvidenceSettings", "Finding",
           "cells_table", "claims_table", "evaluate", "evaluate_all"]

#: Every verdict a claim can get.
VERDICTS = ("holds", "does not hold", "depends", "not measurable", "no data")
#: Columns of :func:`claims_table` (the first four are the report's claims.csv schema).
CLAIM_COLUMNS = ["claim", "section", "verdict", "evidence", "depends_on", "reading", "id",
                 "time_check"]
#: Columns of :func:`cells_table`.
CELL_COLUMNS = ["id", "part", "what", "terrain", "level", "seeds", "estimate", "low", "high",
                "unit", "outcome", "from_times"]
_HOLDS, _FAILS, _DEPENDS = VERDICTS[:3]
_DIMS = {"at": "view", "better": "mapper", "other": "mapper", "mapper": "mapper",
         "case": "case", "x": "parameter", "param": "parameter"}
_PRIORITY = ("metric", "view", "mapper", "case", "parameter")


@dataclass(frozen=True)
class EvidenceSettings(Record):
    """How a claim's cells are judged: the interval and the seeds it needs (module docstring)."""

    OWNER = "evidence"

    level: float = param(CONFIDENCE, lambda v: 0 < v < 1, "0 < level < 1",
                         "confidence level of the bootstrap intervals")
    n_resamples: int = param(2000, lambda v: v >= 1, "n_resamples >= 1", "bootstrap resamples")
    seed: int = param(0, lambda v: v >= 0, "seed >= 0", "bootstrap seed")
    min_seeds: int = param(2, lambda v: v >= 1, "min_seeds >= 1",
                           "fewest seeds that make an interval (fewer: inconclusive)")
    size: str | None = param(None, bool, "a column name",
                             "a column replacing basis_functions in every check (Octomap's "
                             "occupied cells only: occupied_cells)")


@dataclass(frozen=True)
class Finding:
    """A claim's verdict, what it depends on, the evidence text, the per-cell numbers and
    how its times were judged (``time_check``, see the module docstring)."""

    claim: Claim
    verdict: str
    depends_on: str
    evidence: str
    cells: pd.DataFrame
    time_check: str = ""


def _outcome(low: float, high: float, seeds: int, m: CheckValues, min_seeds: int) -> str:
    if seeds < min_seeds or np.isnan(low) or np.isnan(high):  # inf: an unbounded side
        return "inconclusive"
    if m.relation == "undecided":
        return _HOLDS if low <= 0 <= high else _FAILS
    if m.relation == "similar":
        if -m.band <= low and high <= m.band:
            return _HOLDS
        return _FAILS if low > m.band or high < -m.band else "inconclusive"
    return _HOLDS if low > m.threshold else _FAILS if high < m.threshold else "inconclusive"


def _interval(group: pd.DataFrame, options: EvidenceSettings) -> Interval:
    """The bootstrap interval of one cell's seeds (of their bounds, where they have them)."""
    if "low" in group:
        return bootstrap_bounds(group["value"].to_numpy(), group["low"].to_numpy(),
                                group["high"].to_numpy(), level=options.level,
                                n_resamples=options.n_resamples, seed=options.seed)
    return bootstrap_ci(group["value"].to_numpy(), options.level, options.n_resamples,
                        options.seed)


def _cells(m: CheckValues, options: EvidenceSettings) -> pd.DataFrame:
    rows = []
    for (terrain, level), group in m.stats.groupby(["terrain", "level"], dropna=False,
                                                   sort=True):
        ci = _interval(group, options)
        rows.append({"terrain": terrain, "level": level, "seeds": ci.seeds,
                     "estimate": ci.estimate, "low": ci.low, "high": ci.high,
                     "outcome": _outcome(ci.low, ci.high, ci.seeds, m, options.min_seeds)})
    return pd.DataFrame(rows, columns=["terrain", "level", "seeds", "estimate", "low", "high",
                                       "outcome"])


def _cell_verdict(cells: pd.DataFrame, level_kind: str) -> tuple[str, str]:
    outcomes = set(cells["outcome"])
    if outcomes in ({_HOLDS}, {_FAILS}):
        return outcomes.pop(), ""
    decisive = cells[cells["outcome"] != "inconclusive"]
    if decisive["outcome"].nunique() < 2:
        return _DEPENDS, "uncertainty"
    per_terrain = decisive.groupby("terrain")["outcome"].agg(lambda s: s.iloc[0]
                                                             if s.nunique() == 1 else "mixed")
    dims = [name for name, varies in (
        ("terrain", per_terrain[per_terrain != "mixed"].nunique() > 1),
        (level_kind or "setting", (per_terrain == "mixed").any())) if varies]
    return _DEPENDS, ", ".join(dims) or "terrain"


def _property(p: Property) -> tuple[str, str]:
    from alte.mappers import registry

    values = {m: bool(getattr(registry.resolve(m), p.attribute)) for m in (*p.true, *p.false)}
    wrong = [m for m in p.true if not values[m]] + [m for m in p.false if values[m]]
    text = ", ".join(f"{mapper_title(m)}: {p.attribute} = {values[m]}" for m in values)
    return (_FAILS if wrong else _HOLDS), f"our implementations: {text}"


Result = tuple[str, str, str, pd.DataFrame, str]


def _crosscheck_text(m: CheckValues, cells: pd.DataFrame, options: EvidenceSettings) -> str:
    """The cost's statistic measured again on the CPU time: its verdict and the cells where
    the two decide opposite ways (readings of one run, not judged within their spread)."""
    if m.crosscheck is None:
        return ""
    time = _cells(m.crosscheck, options)
    time = time[time["seeds"] > 0]
    if time.empty:
        return " Cross-check on the CPU time: no value."
    verdict, depends = _cell_verdict(time, m.crosscheck.level_kind)
    both = cells.merge(time, on=["terrain", "level"], suffixes=("", "_time"))
    decided = {_HOLDS, _FAILS}
    against = both[both["outcome"].isin(decided) & both["outcome_time"].isin(decided)
                   & (both["outcome"] != both["outcome_time"])]
    where = ", ".join(dict.fromkeys(against["terrain"].astype(str)))
    verdict += f" ({depends})" if depends else ""
    contra = f"it contradicts the cost on {where}" if where else "no cell contradicts the cost"
    text = check_text(m.crosscheck, time)
    return f" Cross-check on the CPU time: {text} -> {verdict}; {contra}."


def _one(check: Check, table: pd.DataFrame, options: EvidenceSettings,
         variants: pd.DataFrame | None = None) -> Result:
    """(verdict, depends_on, evidence, cells, time check) of one check (``variants``: the
    grid's rows of every ablation variant, which a :class:`Contrast` reads)."""
    if isinstance(check, NotMeasurable):
        return "not measurable", "", check.reason, pd.DataFrame(), ""
    if isinstance(check, Property):
        verdict, text = _property(check)
        return verdict, "", text, pd.DataFrame(), ""
    if isinstance(check, Contrast):
        table = variants if variants is not None else table
    try:
        m = measure_check(check, table)
    except NoDataError as err:
        return "no data", "", f"not measured: {err}", pd.DataFrame(), ""
    cells = _cells(m, options)
    cells = cells[cells["seeds"] > 0].reset_index(drop=True)
    if cells.empty:
        return "no data", "", f"{m.what}: no terrain and seed gives a value", cells, ""
    verdict, depends = _cell_verdict(cells, m.level_kind)
    if m.read_from_times and (cells["outcome"] == "inconclusive").any():
        depends = "uncertainty"  # which of its cells are decided moves with the readings
    scale = np.exp if m.ratio else (lambda v: v)
    shown = cells.assign(what=m.what, unit=m.unit, estimate=scale(cells["estimate"]),
                         low=scale(cells["low"]), high=scale(cells["high"]),
                         from_times=m.read_from_times)
    text = check_text(m, cells) + _crosscheck_text(m, cells, options)
    return verdict, depends, text, shown, time_check_text(m)


def _part_dims(good: Sequence[Check], bad: Sequence[Check]) -> list[str]:
    """What tells holding parts from failing ones: per pair the first of metric, view,
    mapper, case, parameter that differs."""
    dims = set()
    for a, b in ((a, b) for a in good for b in bad):
        differ = ({"metric"} if type(a) is not type(b) else
                  {_DIMS.get(f.name, "metric") for f in fields(a)
                   if getattr(a, f.name) != getattr(b, f.name)})
        dims.add(next((d for d in _PRIORITY if d in differ), "metric"))
    return sorted(dims, key=_PRIORITY.index)


def _combine(parts: Sequence[Check], results: Sequence[Result]) -> tuple[str, str]:
    verdicts = [r[0] for r in results]
    tested = [v for v in verdicts if v in (_HOLDS, _FAILS, _DEPENDS)]
    if not tested:
        return ("no data" if "no data" in verdicts else "not measurable"), ""
    if set(tested) == {_FAILS}:
        return _FAILS, ""
    if set(verdicts) == {_HOLDS}:
        return _HOLDS, ""
    good = [p for p, v in zip(parts, verdicts, strict=True) if v == _HOLDS]
    bad = [p for p, v in zip(parts, verdicts, strict=True) if v == _FAILS]
    inner = [d for r in results for d in r[1].split(", ") if d]
    untested = ["untested part"] if len(tested) < len(verdicts) else []
    dims = _part_dims(good, bad) + inner + untested
    return _DEPENDS, ", ".join(dict.fromkeys(dims)) or "uncertainty"


def _resized(check: Check | AllOf, size: str | None) -> Check | AllOf:
    """``check`` with every ``basis_functions`` column replaced by ``size``."""
    if size is None:
        return check
    if isinstance(check, AllOf):
        return AllOf(tuple(renamed(p, "basis_functions", size) for p in check.parts))
    return renamed(check, "basis_functions", size)


def _evaluate(claim: Claim, table: pd.DataFrame, options: EvidenceSettings,
              cache: dict[Check, Result] | None = None,
              variants: pd.DataFrame | None = None) -> Finding:
    check = _resized(claim.check, options.size)
    parts = check.parts if isinstance(check, AllOf) else (check,)
    cache = {} if cache is None else cache
    results = []
    for part in parts:
        if part not in cache:  # many claims share a check: measure it once per table
            cache[part] = _one(part, table, options, variants)
        results.append(cache[part])
    checks = "; ".join(dict.fromkeys(r[4] for r in results if r[4]))
    if len(parts) == 1:
        verdict, depends, text, cells, _ = results[0]
    else:
        verdict, depends = _combine(parts, results)
        text = " ".join(f"({i}) {r[2]} -> {r[0]}{' (' + r[1] + ')' if r[1] else ''}."
                        for i, r in enumerate(results, 1))
        cells = pd.concat([r[3].assign(part=i) for i, r in enumerate(results, 1)
                           if not r[3].empty] or [pd.DataFrame()], ignore_index=True)
    if not cells.empty:
        text = (f"Means over seeds with {options.level:.0%} percentile-bootstrap intervals. "
                + text)
    cells = cells.assign(id=claim.id) if not cells.empty else pd.DataFrame(columns=CELL_COLUMNS)
    if "part" not in cells:
        cells["part"] = 1
    return Finding(claim, verdict, depends, text, cells.reindex(columns=CELL_COLUMNS), checks)


def evaluate(claim: Claim, table: pd.DataFrame, options: EvidenceSettings | None = None,
             variants: pd.DataFrame | None = None) -> Finding:
    """The verdict on ``claim`` from a trade-off table (see the module docstring);
    ``variants``: the grid's rows of every ablation variant (a ``variant`` column, the
    base grid as ``base``), for the claims that contrast them."""
    ready = prepare(variants) if variants is not None else None
    return _evaluate(claim, prepare(table), options or EvidenceSettings(), variants=ready)


def evaluate_all(claims: Sequence[Claim], table: pd.DataFrame,
                 options: EvidenceSettings | None = None,
                 variants: pd.DataFrame | None = None) -> list[Finding]:
    """:func:`evaluate` for every claim (the tables are checked and prepared once)."""
    prepared = prepare(table)
    ready = prepare(variants) if variants is not None else None
    cache: dict[Check, Result] = {}
    return [_evaluate(c, prepared, options or EvidenceSettings(), cache, ready) for c in claims]


def claims_table(findings: Sequence[Finding]) -> pd.DataFrame:
    """The report's claims table: claim (the quote), section, verdict, evidence, then
    depends_on, reading, id and time_check."""
    return pd.DataFrame([{"claim": f.claim.quote, "section": f.claim.section,
                          "verdict": f.verdict, "evidence": f.evidence,
                          "depends_on": f.depends_on, "reading": f.claim.reading,
                          "id": f.claim.id, "time_check": f.time_check} for f in findings],
                        columns=CLAIM_COLUMNS)


def cells_table(findings: Sequence[Finding]) -> pd.DataFrame:
    """Every measured cell of every claim (ratios shown as factors, unit ``x``)."""
    frames = [f.cells for f in findings if not f.cells.empty]
    return (pd.concat(frames, ignore_index=True) if frames
            else pd.DataFrame(columns=CELL_COLUMNS))
