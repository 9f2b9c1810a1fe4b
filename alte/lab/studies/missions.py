"""Whole-mission evidence: the full trade-off grid's verdicts, committed beside the report's.

The report's grid maps 20 scans per mission over three seeds; the thesis judged whole
missions. The full grid (``notebooks/sweeps/tradeoff-full.yaml``: every scan, five
seeds) takes hours, so its evidence is made once and committed as small tables in one
folder (:data:`WHOLE_MISSIONS`), the same files ``make report`` writes for the short
missions:

* ``claims.csv`` (every claim's verdict), ``equal_size.csv``, ``equal_fidelity.csv``;
* ``fronts.csv``: the fronts' points (each map on a mapper's Pareto front of basis
  functions against each metric read at equal size, per terrain and seed);
* ``claims_cells.csv``: every cell (terrain, size or fidelity level) behind the verdicts;
* ``provenance.json``: the command and commit that made them, the runs, their CPU
  seconds and wall time, the machine.

``alte sweep SPEC --evidence FOLDER`` runs the grid (resumable) and writes the folder
(:func:`write_mission_evidence`). ``make report`` never recomputes it: the chapter 5
notebook reads it (:func:`load_mission_evidence`) and writes ``claims_missions.csv``
(:func:`compare_verdicts`): per claim the 20-scan verdict and the whole-mission one,
each with what it depends on, ``differs`` where they are not the same, and ``why``: for
a differing claim, the outcomes of its cells per terrain on each side (what moved).
"""

from __future__ import annotations

import json
import os
import subprocess
from dataclasses import asdict, dataclass
from pathlib import Path

import pandas as pd

from alte import __version__
from alte.errors import ReportError
from alte.lab.studies.analysis.evidence_tables import EQUAL_SIZE, write_evidence
from alte.lab.studies.analysis.tables import write_csv
from alte.lab.studies.analysis.tradeoff import fronts, prepare
from alte.types import JSONDict

__all__ = ["CELLS", "EVIDENCE_TABLES", "PROVENANCE", "WHOLE_MISSIONS", "MissionEvidence",
           "Provenance", "compare_verdicts", "front_points", "git_commit", "load_mission_evidence",
           "outcome_summary", "write_comparison", "write_mission_evidence"]

#: Where the whole-mission evidence is committed (relative to the repository root).
WHOLE_MISSIONS = Path("notebooks/sweeps/tradeoff-full")
#: The tables of the evidence folder (CSV stems).
EVIDENCE_TABLES = ("claims", "equal_size", "equal_fidelity", "fronts")
#: The cells behind the verdicts (CSV stem; folders written before it existed lack it).
CELLS = "claims_cells"
#: The provenance file of the evidence folder.
PROVENANCE = "provenance.json"
#: The comparison table ``make report`` writes.
COMPARISON = "claims_missions"
_WRITTEN_TOO = ("key_equal_size", "key_equal_fidelity")  # not kept
#: A cell's outcome as counted in ``why``.
_OUTCOME_WORDS = {"holds": "hold", "does not hold": "do not hold", "inconclusive": "undecided"}


@dataclass(frozen=True)
class Provenance:
    """What made an evidence folder: the command and commit, the spec's runs (``ran`` of
    them by that command, the others by earlier, interrupted ones: the sweep resumes),
    the CPU seconds of all runs, the command's wall seconds and the machine."""

    command: str
    commit: str
    spec: str
    runs: int
    ran: int
    frames: int | None
    seeds: list[int]
    cpu_s: float
    wall_s: float
    started: str
    finished: str
    machine: JSONDict
    version: str = __version__


@dataclass(frozen=True)
class MissionEvidence:
    """An evidence folder, read: its tables and provenance."""

    folder: Path
    claims: pd.DataFrame
    equal_size: pd.DataFrame
    equal_fidelity: pd.DataFrame
    fronts: pd.DataFrame
    provenance: Provenance
    cells: pd.DataFrame


def git_commit(where: str | os.PathLike[str] = ".") -> str:
    """The checked-out commit (with ``-dirty`` when files differ), or ``unknown``."""
    try:
        head = subprocess.run(["git", "-C", str(where), "rev-parse", "HEAD"], check=True,
                              capture_output=True, text=True, timeout=30).stdout.strip()
        dirty = subprocess.run(["git", "-C", str(where), "status", "--porcelain",
                                "--untracked-files=no"], check=True, capture_output=True,
                               text=True, timeout=30).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return "unknown"
    return f"{head}-dirty" if dirty else head


def front_points(table: pd.DataFrame) -> pd.DataFrame:
    """The maps on each mapper's front of basis functions against each equal-size metric
    (per terrain and seed): terrain, mapper, seed, metric, params, basis_functions, value."""
    prepared = prepare(table)
    parts = []
    for metric, higher in EQUAL_SIZE:
        if metric not in prepared or prepared[metric].isna().all():
            continue
        rows = fronts(prepared, "basis_functions", metric, higher_is_better=higher)
        on = rows[rows["on_front"]]
        parts.append(pd.DataFrame({"terrain": on["terrain"], "mapper": on["mapper"],
                                   "seed": on["seed"], "metric": metric,
                                   "params": on["params"], "basis_functions": on["x"],
                                   "value": on["y"]}))
    columns = ["terrain", "mapper", "seed", "metric", "params", "basis_functions", "value"]
    return pd.concat(parts, ignore_index=True) if parts else pd.DataFrame(columns=columns)


def write_mission_evidence(table: pd.DataFrame, folder: str | os.PathLike[str],
                           provenance: Provenance) -> Path:
    """Evaluate the claims on a trade-off ``table``
    (:func:`alte.lab.studies.tradeoff.grid.tradeoff_table`)
    and write the evidence folder (module docstring), replacing its files."""
    out = Path(folder)
    write_evidence(table, out, overwrite=True)
    for name in _WRITTEN_TOO:  # the folder keeps the tables the comparison reads
        (out / f"{name}.csv").unlink(missing_ok=True)
    write_csv(front_points(table), out, "fronts", overwrite=True)
    (out / PROVENANCE).write_text(json.dumps(asdict(provenance), indent=1) + "\n",
                                  encoding="utf-8")
    return out


def _read(folder: Path, name: str) -> pd.DataFrame:
    path = folder / f"{name}.csv"
    try:
        return pd.read_csv(path, keep_default_na=False, na_values=[""])
    except (OSError, ValueError, pd.errors.EmptyDataError) as err:
        raise ReportError(f"whole-mission evidence {path}: unreadable ({err})") from err


def load_mission_evidence(folder: str | os.PathLike[str]) -> MissionEvidence:
    """Read an evidence folder; a missing or unreadable file raises :class:`ReportError`
    naming it."""
    root = Path(folder)
    missing = [f"{n}.csv" for n in EVIDENCE_TABLES if not (root / f"{n}.csv").is_file()]
    if not (root / PROVENANCE).is_file():
        missing.append(PROVENANCE)
    if missing:
        raise ReportError(f"whole-mission evidence {root}: missing {', '.join(missing)} (made "
                          "by a sweep given an evidence folder)")
    try:
        raw = json.loads((root / PROVENANCE).read_text(encoding="utf-8"))
        provenance = Provenance(**raw)
    except (OSError, ValueError, TypeError) as err:
        raise ReportError(f"whole-mission evidence {root / PROVENANCE}: unreadable "
                          f"({err})") from err
    claims, at_size, at_fidelity, points = (_read(root, n) for n in EVIDENCE_TABLES)
    cells = _read(root, CELLS) if (root / f"{CELLS}.csv").is_file() else pd.DataFrame()
    return MissionEvidence(root, claims, at_size, at_fidelity, points, provenance, cells)


def outcome_summary(cells: pd.DataFrame) -> str:
    """A claim's cells as outcome counts per terrain, e.g. ``sim_lan_1: 3 hold, 1 undecided;
    sim_nav_1: 2 do not hold`` (empty without cells)."""
    if cells.empty or "terrain" not in cells:
        return ""
    parts = []
    for terrain, group in cells.groupby("terrain", sort=True):
        counts = group["outcome"].value_counts()
        words = [f"{counts[o]} {_OUTCOME_WORDS.get(o, o)}" for o in
                 (*_OUTCOME_WORDS, *sorted(set(counts.index) - set(_OUTCOME_WORDS)))
                 if o in counts]
        parts.append(f"{terrain}: {', '.join(words)}")
    return "; ".join(parts)


def _why(claim_id: str, short_cells: pd.DataFrame, whole_cells: pd.DataFrame) -> str:
    """What moved between the two grids for one claim: its cells' outcomes on each side."""
    sides = [(label, outcome_summary(cells[cells["id"] == claim_id]) if "id" in cells else "")
             for label, cells in (("20 scans", short_cells), ("whole missions", whole_cells))]
    return " | ".join(f"{label}: {text}" for label, text in sides if text)


def compare_verdicts(short: pd.DataFrame, whole: pd.DataFrame,
                     short_cells: pd.DataFrame | None = None,
                     whole_cells: pd.DataFrame | None = None) -> pd.DataFrame:
    """Per claim (``id``) of the short-mission claims table: section, claim, the verdict and
    what it depends on in each, ``differs`` and ``why`` (module docstring; from the claims'
    cells when given); a claim only one table has shows ``absent`` in the other."""
    keep = ["id", "verdict", "depends_on"]
    only_whole = whole.loc[~whole["id"].isin(short["id"]), ["id", "section", "claim"]]
    both = pd.concat([short[["id", "section", "claim", *keep[1:]]], only_whole],
                     ignore_index=True).merge(whole[keep], on="id", how="left",
                                              suffixes=("_20_scans", "_whole_missions"))
    for side in ("_20_scans", "_whole_missions"):
        both[f"verdict{side}"] = both[f"verdict{side}"].fillna("absent")
        both[f"depends_on{side}"] = both[f"depends_on{side}"].fillna("")
    both["differs"] = both["verdict_20_scans"] != both["verdict_whole_missions"]
    empty = pd.DataFrame()
    both["why"] = [_why(i, empty if short_cells is None else short_cells,
                        empty if whole_cells is None else whole_cells) if moved else ""
                   for i, moved in zip(both["id"], both["differs"], strict=True)]
    order = ["id", "section", "claim", "verdict_20_scans", "verdict_whole_missions", "differs",
             "depends_on_20_scans", "depends_on_whole_missions", "why"]
    return both[order].reset_index(drop=True)


def write_comparison(short: pd.DataFrame, folder: str | os.PathLike[str] | None,
                     tables_dir: str | os.PathLike[str]) -> pd.DataFrame:
    """:func:`compare_verdicts` of the short-mission claims and the evidence ``folder``,
    written to ``tables_dir/claims_missions.csv``; empty (nothing written) when no
    evidence is committed there."""
    if folder is None or not (Path(folder) / PROVENANCE).is_file():
        return compare_verdicts(short.iloc[:0], short.iloc[:0])
    found = load_mission_evidence(folder)
    own = Path(tables_dir) / f"{CELLS}.csv"
    short_cells = pd.read_csv(own, keep_default_na=False) if own.is_file() else None
    table = compare_verdicts(short, found.claims, short_cells, found.cells)
    write_csv(table, tables_dir, COMPARISON, overwrite=True)
    return table
