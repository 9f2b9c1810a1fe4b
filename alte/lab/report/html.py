"""HTML for the report: executed notebooks (nbconvert), a run's front page, the top index.

Pages are rendered from jinja2 templates (``alte/lab/report/templates``, shipped as package
data) with autoescaping; links are relative, so a run folder can be moved or served as
it is. A run's page is built as data first (:mod:`alte.lab.report.page`), then rendered.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from typing import TYPE_CHECKING

from alte.errors import ReportError
from alte.fsutil import atomic_path
from alte.lab.report.page import run_page
from alte.lab.report.runs import record_runs
from alte.types import JSONMap

if TYPE_CHECKING:
    import jinja2

__all__ = ["notebook_to_html", "run_index_html", "top_index_html", "write_html"]


def write_html(path: str | os.PathLike[str], body: str) -> Path:
    """Write ``body`` to ``path`` atomically (overwriting)."""
    path = Path(path)
    with atomic_path(path, overwrite=True) as tmp:
        tmp.write_text(body, encoding="utf-8")
        tmp.chmod(0o644)  # a web page: readable like papermill's notebooks, not 0600
    return path


def notebook_to_html(ipynb: str | os.PathLike[str], out: str | os.PathLike[str]) -> Path:
    """Convert an executed notebook to a standalone HTML page with nbconvert."""
    import nbformat
    from nbconvert import HTMLExporter

    try:
        nb = nbformat.read(str(ipynb), as_version=4)
        body, _ = HTMLExporter(embed_images=True).from_notebook_node(nb)
    except Exception as err:
        raise ReportError(f"cannot convert {ipynb} to HTML: {err}") from err
    return write_html(out, body)


@cache
def _environment() -> jinja2.Environment:
    import jinja2

    return jinja2.Environment(loader=jinja2.PackageLoader("alte.lab.report", "templates"),
                              autoescape=True, undefined=jinja2.StrictUndefined,
                              trim_blocks=True, lstrip_blocks=True, keep_trailing_newline=True)


def _render(template: str, **context: object) -> str:
    import jinja2

    try:
        return str(_environment().get_template(template).render(**context))
    except jinja2.TemplateError as err:
        raise ReportError(f"report template {template}: {err}") from err


def run_index_html(record: JSONMap, run_dir: str | os.PathLike[str],
                   tables: Sequence[Path]) -> str:
    """A run's front page: claims and verdicts, trade-offs, key tables, then each
    chapter's results and captioned figures, failures flagged at the top."""
    page = run_page(record, run_dir, tables)
    return _render("run.html.j2", title=page.title, page=page)


@dataclass(frozen=True)
class _Listed:
    name: str
    href: str
    mode: str
    notebooks: int | None
    failed: int | None
    state: str


def _listed(rel: str, record: JSONMap | None) -> _Listed:
    name, href = Path(rel).name, f"{rel}/index.html"
    if record is None:
        return _Listed(name, href, "", None, None, "interrupted (unfinished)")
    runs = record_runs(record)
    bad = sum(r["status"] != "ok" for r in runs)
    state = f"{record['mode']}, {len(runs)} runs, {bad} failed"
    return _Listed(name, href, str(record["mode"]), len(runs), bad, state)


def top_index_html(runs: Sequence[tuple[str, JSONMap | None]],
                   latest: str | None) -> str:
    """``reports/index.html``: a link to the latest run and every run, newest first."""
    return _render("top.html.j2", title="alte reports", latest=latest,
                   runs=[_listed(rel, record) for rel, record in runs])
