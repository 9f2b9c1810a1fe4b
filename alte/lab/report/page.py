"""The front page as data: what a run's ``index.html`` shows, built from its folder.

:func:`run_page` reads the run record, each notebook's ``results.json`` and figures and
the run's tables, and returns a :class:`RunPage` the template renders: the bottom line
first (:mod:`alte.lab.report.answer`, from the run's tables), then the claims
(``tables/claims.csv``) grouped by the thesis' question they bear on, each "depends"
with its condition, the trade-off figures and tables, the key tables with the thesis'
values beside ours, then one section per notebook run with its headline results, captioned
figures and links; results as labelled scalars, tables via :mod:`alte.lab.report.tableview`.
"""

from __future__ import annotations

import json
import os
from collections.abc import Hashable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path

import pandas as pd

from alte.lab.report.answer import AnswerView, answer_view
from alte.lab.report.captions import (
    KEY_TABLES,
    TRADEOFF_PREFIXES,
    KeyTable,
    caption,
    chapter_title,
    saved_figures,
)
from alte.lab.report.plan import PLAN
from alte.lab.report.tableview import TableView, cell_text, header, table_view
from alte.lab.studies.thesis.claims.questions import QUESTIONS, question
from alte.types import JSON, JSONMap

__all__ = ["CLAIMS_CSV", "MISSIONS_CSV", "ClaimGroup", "ClaimRow", "FigureItem", "RunPage",
           "RunSection", "TableItem", "run_page"]

#: The claims table a run's chapter 5 notebook writes into ``tables/``.
CLAIMS_CSV = "claims.csv"
#: Its verdicts beside the committed whole-mission ones (``alte.lab.studies.missions``).
MISSIONS_CSV = "claims_missions.csv"
#: Tables up to this many rows are shown inline; longer ones are linked.
INLINE_ROWS = 60
_VERDICT_CSS = {"holds": "holds", "does not hold": "fails", "depends": "depends"}


@dataclass(frozen=True)
class ClaimRow:
    """One claim with its verdict (``css``: the verdict's style class) and, where the
    whole-mission evidence is committed, its verdict on whole missions (``whole``,
    ``whole_css``, ``whole_depends_on``), whether the two differ and what moved
    (``whole_why``: the cells' outcomes per terrain on each side)."""

    section: str
    claim: str
    verdict: str
    css: str
    depends_on: str
    evidence: str
    reading: str
    condition: str = ""
    question: str = ""
    whole: str = ""
    whole_css: str = ""
    whole_depends_on: str = ""
    differs: bool = False
    whole_why: str = ""


@dataclass(frozen=True)
class ClaimGroup:
    """The claims bearing on one of the thesis' questions, with their verdict counts."""

    anchor: str
    title: str
    verdicts: list[tuple[str, int, str]]
    claims: list[ClaimRow]


@dataclass(frozen=True)
class FigureItem:
    """A figure: image path (relative to the run folder), title and caption."""

    src: str
    title: str
    caption: str


@dataclass(frozen=True)
class TableItem:
    """A table: title, caption, CSV link and its view (None when too long to show)."""

    title: str
    caption: str
    href: str
    view: TableView | None


@dataclass(frozen=True)
class RunSection:
    """One notebook run: status, links, headline results and figures."""

    anchor: str
    title: str
    status: str
    seconds: float
    links: list[tuple[str, str]]
    error: str
    results: list[tuple[str, str]]
    figures: list[FigureItem]


@dataclass
class RunPage:
    """Everything a run's index page shows, in page order."""

    title: str
    summary: str
    failed: list[tuple[str, str]]
    problems: list[str]
    claims: list[ClaimRow]
    verdicts: list[tuple[str, int, str]]
    answer: AnswerView | None = None
    groups: list[ClaimGroup] = field(default_factory=list)
    tradeoff: list[FigureItem] = field(default_factory=list)
    key_tables: list[TableItem] = field(default_factory=list)
    sections: list[RunSection] = field(default_factory=list)
    tables: list[TableItem] = field(default_factory=list)


def _notebook(name: str) -> str:
    """The source notebook stem of a planned run name (the run name when unplanned)."""
    for entry in PLAN:
        if entry.name == name:
            return Path(entry.notebook).stem
    return name


def _read_json(path: Path) -> JSONMap:
    try:
        return _map(json.loads(path.read_text(encoding="utf-8")))
    except (OSError, ValueError):
        return {}


def _map(value: JSON) -> JSONMap:
    """``value`` if it is a JSON object, else an empty one."""
    return value if isinstance(value, Mapping) else {}


def _list(value: JSON) -> Sequence[JSON]:
    """``value`` if it is a JSON list, else an empty one."""
    return value if isinstance(value, Sequence) and not isinstance(value, str) else []


def _seconds(value: JSON) -> float:
    return float(value) if isinstance(value, int | float) else 0.0


def _scalar_text(key: str, value: JSON) -> str | None:
    """A headline value as text, or None for what is no headline (nested data, paths)."""
    if isinstance(value, list) and len(value) <= 8 and all(
            isinstance(v, int | float | str) for v in value):
        return ", ".join(cell_text(v, key) for v in value) or None
    if isinstance(value, int | float) or (isinstance(value, str) and "/" not in value
                                          and len(value) <= 80):
        return cell_text(value, key)
    return None


def _results(data: JSONMap) -> list[tuple[str, str]]:
    out = []
    for key, value in data.items():
        text = _scalar_text(key, value) if key != "captions" else None
        if text is not None:
            out.append((header(key), text))
    return out


def _figures(run_dir: Path, name: str, params: JSONMap, own: JSONMap) -> list[FigureItem]:
    items = []
    for png, saved in saved_figures(run_dir / name / "figures"):
        text = caption(png.stem, saved, params, own)
        items.append(FigureItem(png.relative_to(run_dir).as_posix(), text.title, text.text))
    return items


def _is_tradeoff(item: FigureItem) -> bool:
    return Path(item.src).stem.startswith(TRADEOFF_PREFIXES)


def _section(run: JSONMap, run_dir: Path) -> RunSection:
    name = str(run["name"])
    params = _map(run.get("parameters"))
    data = _read_json(run_dir / name / "results.json")
    links = [(label, str(run[key])) for key, label in (("html", "executed notebook"),
                                                       ("notebook", "notebook (.ipynb)"))
             if run.get(key)]
    return RunSection(name, chapter_title(_notebook(name), name, params), str(run["status"]),
                      _seconds(run.get("seconds")), links, str(run.get("error") or ""),
                      _results(data), _figures(run_dir, name, params, _map(data.get("captions"))))


def _whole_missions(tables_dir: Path) -> dict[str, Mapping[Hashable, object]]:
    """Per claim id, its row of ``claims_missions.csv`` (empty without that table)."""
    path = tables_dir / MISSIONS_CSV
    if not path.is_file():
        return {}
    frame = pd.read_csv(path, keep_default_na=False)
    return {str(r["id"]): r for r in frame.to_dict(orient="records")}


def _claims(tables_dir: Path) -> list[ClaimRow]:
    path = tables_dir / CLAIMS_CSV
    if not path.is_file():
        return []
    frame = pd.read_csv(path, keep_default_na=False)
    whole = _whole_missions(tables_dir)
    rows = []
    for r in frame.to_dict(orient="records"):
        other = whole.get(str(r.get("id", "")), {})
        verdict = str(other.get("verdict_whole_missions", ""))
        rows.append(ClaimRow(
            str(r.get("section", "")), str(r["claim"]), str(r["verdict"]),
            _VERDICT_CSS.get(str(r["verdict"]), "untested"), str(r.get("depends_on", "")),
            str(r.get("evidence", "")), str(r.get("reading", "")), str(r.get("condition", "")),
            str(r.get("question", "")) or _question(str(r.get("id", ""))), verdict,
            _VERDICT_CSS.get(verdict, "untested") if verdict else "",
            str(other.get("depends_on_whole_missions", "")),
            bool(verdict) and verdict != str(r["verdict"]), str(other.get("why", ""))))
    return rows


def _question(claim_id: str) -> str:
    """The question of a claim by id (claims tables written before the column existed)."""
    from alte.errors import ParameterError
    from alte.lab.studies.thesis.claims import claim

    try:
        return question(claim(claim_id))
    except ParameterError:
        return ""


def _groups(claims: Sequence[ClaimRow]) -> list[ClaimGroup]:
    """The claims by question, in the page order of :data:`QUESTIONS` (unknown last)."""
    order = [*QUESTIONS, ""]
    groups = []
    for key in order:
        mine = [c for c in claims if (c.question if c.question in QUESTIONS else "") == key]
        if mine:
            groups.append(ClaimGroup(f"claims-{key or 'other'}",
                                     QUESTIONS.get(key, "Other claims"), _counts(mine), mine))
    return groups


def _table(csv: Path, run_dir: Path, shown: KeyTable) -> TableItem:
    """A CSV as a page table, as ``shown`` says (title, text, columns hidden, row limit)."""
    href = csv.relative_to(run_dir).as_posix()
    try:
        frame = pd.read_csv(csv)
    except (OSError, ValueError, pd.errors.EmptyDataError) as err:
        return TableItem(shown.title, f"unreadable: {err}", href, None)
    visible = frame.drop(columns=[c for c in shown.hide if c in frame])
    view = table_view(visible, key=shown.key) if len(frame) <= shown.rows else None
    shape = f"{len(frame):,} rows, {len(frame.columns)} columns"
    return TableItem(shown.title, f"{shown.text} ({shape})".lstrip(), href, view)


def _counts(claims: Sequence[ClaimRow]) -> list[tuple[str, int, str]]:
    order = ("holds", "does not hold", "depends", "not measurable", "no data")
    counts = {v: sum(c.verdict == v for c in claims) for v in order}
    return [(v, n, _VERDICT_CSS.get(v, "untested")) for v, n in counts.items() if n]


def run_page(record: JSONMap, run_dir: str | os.PathLike[str],
             tables: Sequence[Path]) -> RunPage:
    """The page model of the run in ``run_dir`` (its record, files and ``tables``)."""
    run_dir = Path(run_dir)
    runs = [r for r in _list(record["runs"]) if isinstance(r, Mapping)]
    failed = [(str(r["name"]), str(r["status"])) for r in runs if r["status"] != "ok"]
    summary = (f"{record['mode']} mode, started {record['started']}: {len(runs)} notebooks, "
               f"{len(failed)} failed, {_seconds(record['seconds']):.1f} s in all")
    claims = _claims(run_dir / "tables")
    page = RunPage(f"alte report {run_dir.name}", summary, failed,
                   [str(p) for p in _list(record.get("problems"))], claims, _counts(claims),
                   answer_view(run_dir / "tables"), _groups(claims))
    for run in runs:
        section = _section(run, run_dir)
        page.tradeoff += [f for f in section.figures if _is_tradeoff(f)]
        page.sections.append(replace(section, figures=[
            f for f in section.figures if not _is_tradeoff(f)]))
    by_name = {t.stem: t for t in tables}
    page.key_tables = [_table(by_name[k.name], run_dir, k) for k in KEY_TABLES
                       if k.name in by_name]
    keyed = {k.name for k in KEY_TABLES} | {Path(CLAIMS_CSV).stem, Path(MISSIONS_CSV).stem}
    page.tables = [_table(t, run_dir, KeyTable(t.stem, t.name, "", key=False, rows=INLINE_ROWS))
                   for t in tables if t.stem not in keyed]
    return page
