"""The evidence as report tables: claims, their cells, comparisons at equal size and
fidelity, and ablations (what moves a verdict when one thing changes).

:func:`write_evidence` is the one call the chapter 5 notebook makes: it evaluates every
claim on the trade-off table and writes ``claims.csv`` (the front page's claims table;
for a claim that depends, ``condition`` says where it holds and where not,
:mod:`alte.lab.studies.analysis.conditions`; ``question`` the thesis' question it bears on),
``claims_cells.csv`` (every number behind the verdicts), ``equal_size.csv`` and
``equal_fidelity.csv`` (each case's two mappers read off their fronts; mean over seeds
with bootstrap intervals) and their headline rows with units in the headers
(``key_equal_size.csv``: MHD at 1k/5k/20k basis functions; ``key_equal_fidelity.csv``:
basis functions for equal MHD) into the run's tables folder.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from alte.lab.studies.analysis.conditions import conditions
from alte.lab.studies.analysis.evidence import (
    CLAIM_COLUMNS,
    EvidenceSettings,
    Finding,
    cells_table,
    claims_table,
    evaluate_all,
)
from alte.lab.studies.analysis.tables import write_csv
from alte.lab.studies.analysis.tradeoff import equal_fidelity, equal_size, interval_table, prepare
from alte.lab.studies.thesis.claims import CLAIMS, Claim
from alte.lab.studies.thesis.claims.questions import question
from alte.lab.studies.thesis.numbers import CASE_MAPPERS, TERRAIN_CASE

__all__ = [
    "CLAIMS_CSV_COLUMNS",
    "EQUAL_FIDELITY",
    "EQUAL_SIZE",
    "SIZES",
    "EvidenceFiles",
    "ablation_table",
    "ablation_verdicts",
    "comparison_tables",
    "key_table",
    "write_evidence",
]

#: Columns of claims.csv: the claims table's, with each "depends"'s condition
#: (:mod:`alte.lab.studies.analysis.conditions`) and the question the claim bears on
#: (:mod:`alte.lab.studies.thesis.claims.questions`) after ``depends_on``.
CLAIMS_CSV_COLUMNS = [*CLAIM_COLUMNS[:5], "condition", "question", *CLAIM_COLUMNS[5:]]
#: Sizes (basis functions) fidelity is compared at.
SIZES = (1_000.0, 5_000.0, 20_000.0)
#: Metrics compared at equal size: (column, higher is better).
EQUAL_SIZE = (("mhd_m", False), ("accuracy_mean_m", False), ("completeness", True),
              ("height_rmse_m", False))
#: Size and time needed for equal MHD (the time as wall seconds in the mapper calls and as
#: CPU seconds, the one the claims judge: :mod:`alte.lab.studies.analysis.measures`).
EQUAL_FIDELITY = ("basis_functions", "memory_bytes", "elapsed_s", "map_cpu_s")
_SUMMARY = ["case", "terrain", "metric", "level", "mapper", "mean", "low", "high", "seeds"]


@dataclass(frozen=True)
class EvidenceFiles:
    """The findings and the CSVs :func:`write_evidence` wrote."""

    findings: list[Finding]
    claims: Path
    cells: Path
    equal_size: Path
    equal_fidelity: Path
    key_equal_size: Path
    key_equal_fidelity: Path


def _case_table(table: pd.DataFrame, case: str) -> pd.DataFrame:
    cases = table["case"] if "case" in table else table["terrain"].map(TERRAIN_CASE)
    return table[(cases == case) & table["mapper"].isin(CASE_MAPPERS[case])]


def comparison_tables(table: pd.DataFrame, *, sizes: Sequence[float] = SIZES,
                      fidelities: Sequence[float] | None = None,
                      options: EvidenceSettings | None = None
                      ) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Each case's two mappers at equal size (``sizes`` basis functions; reads outside a
    front are left out) and at equal MHD (``fidelities``, default three levels inside
    the fronts' overlap per terrain): (case, terrain, metric, level, mapper, mean, low,
    high, seeds)."""
    options = options or EvidenceSettings()
    prepared = prepare(table)
    at_size, at_fidelity = [], []
    for case, pair in CASE_MAPPERS.items():
        rows = _case_table(prepared, case)
        if set(rows["mapper"]) != set(pair):
            continue
        for metric, higher in EQUAL_SIZE:
            if metric in rows and rows[metric].notna().any():
                reads = equal_size(rows, pair, metric, levels=sizes, higher_is_better=higher)
                at_size.append(_summary(reads, case, metric, options))
        for metric in EQUAL_FIDELITY:
            reads = equal_fidelity(rows, pair, metric, levels=fidelities)
            at_fidelity.append(_summary(reads, case, metric, options))
    return _concat(at_size), _concat(at_fidelity)


def _summary(reads: pd.DataFrame, case: str, metric: str,
             options: EvidenceSettings) -> pd.DataFrame:
    out = interval_table(reads.dropna(subset=["value"]), options.level, options.seed)
    return out.assign(case=case, metric=metric)


def _concat(parts: list[pd.DataFrame]) -> pd.DataFrame:
    frames = [p for p in parts if not p.empty]
    if not frames:
        return pd.DataFrame(columns=_SUMMARY)
    return pd.concat(frames, ignore_index=True)[_SUMMARY]


def key_table(summary: pd.DataFrame, metric: str, level: str, value: str) -> pd.DataFrame:
    """The rows of ``metric`` of a comparison table (:func:`comparison_tables`) with named
    columns: ``level`` for the level read at, ``value`` for the mean and ``ci_low``/
    ``ci_high`` carrying the value's unit suffix (``_m``), so each header shows a unit."""
    part = summary[summary["metric"] == metric]
    unit = next((u for u in ("_m", "_s", "_bytes") if value.endswith(u)), "")
    return pd.DataFrame({"case": part["case"], "terrain": part["terrain"],
                         level: part["level"], "mapper": part["mapper"], value: part["mean"],
                         f"ci_low{unit}": part["low"], f"ci_high{unit}": part["high"],
                         "seeds": part["seeds"]}).reset_index(drop=True)


def write_evidence(table: pd.DataFrame, tables_dir: str | os.PathLike[str], *,
                   claims: Sequence[Claim] = CLAIMS, options: EvidenceSettings | None = None,
                   variants: pd.DataFrame | None = None,
                   overwrite: bool = True) -> EvidenceFiles:
    """Evaluate ``claims`` on the trade-off ``table`` (and the ablation ``variants``' rows,
    for the claims that contrast them) and write the evidence CSVs (see the module
    docstring) into ``tables_dir``."""
    findings = evaluate_all(claims, table, options, variants)
    at_size, at_fidelity = comparison_tables(table, options=options)
    verdicts = claims_table(findings).assign(
        condition=conditions(findings), question=[question(f.claim) for f in findings])
    verdicts = verdicts[CLAIMS_CSV_COLUMNS]
    paths = [write_csv(frame, tables_dir, name, overwrite=overwrite) for frame, name in (
        (verdicts, "claims"), (cells_table(findings), "claims_cells"),
        (at_size, "equal_size"), (at_fidelity, "equal_fidelity"),
        (key_table(at_size, "mhd_m", "basis_functions", "mhd_m"), "key_equal_size"),
        (key_table(at_fidelity, "basis_functions", "mhd_m", "basis_functions"),
         "key_equal_fidelity"))]
    return EvidenceFiles(findings, *paths)


def ablation_table(claims: Sequence[Claim],
                   variants: Mapping[str, tuple[pd.DataFrame, EvidenceSettings]]
                   ) -> pd.DataFrame:
    """One row per claim, one verdict column per variant (a table and its options, e.g.
    another domain or occupancy rule, or ``size="occupied_cells"``), and ``moves``: the
    variants whose verdict differs from the first one's."""
    return ablation_verdicts(claims, {name: evaluate_all(claims, table, options)
                                      for name, (table, options) in variants.items()})


def ablation_verdicts(claims: Sequence[Claim],
                      verdicts: Mapping[str, Sequence[Finding]]) -> pd.DataFrame:
    """:func:`ablation_table` from findings already evaluated (variant -> one finding per
    claim, in the order of ``claims``)."""
    rows = []
    for i, claim in enumerate(claims):
        row: dict[str, str] = {"id": claim.id, "section": claim.section, "claim": claim.quote}
        for name, found in verdicts.items():
            f = found[i]
            row[name] = f.verdict + (f" ({f.depends_on})" if f.depends_on else "")
        first = next(iter(verdicts.values()))[i].verdict if verdicts else ""
        row["moves"] = ", ".join(n for n, found in verdicts.items()
                                 if found[i].verdict != first)
        rows.append(row)
    return pd.DataFrame(rows)
