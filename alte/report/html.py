"""HTML for the report: executed notebooks (nbconvert), a run's index, the top index.

The pages are plain, self-contained HTML: links are relative, figures are shown
as thumbnails linking to the PNG, tables are rendered from their CSVs.
"""

from __future__ import annotations

import html
import json
import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from alte.errors import ReportError
from alte.fsutil import atomic_path

__all__ = ["notebook_to_html", "run_index_html", "top_index_html", "write_html"]

_STYLE = ("<style>body{font-family:sans-serif;margin:2em;max-width:70em}"
          "table{border-collapse:collapse}td,th{border:1px solid #bbb;padding:2px 6px}"
          ".failed{color:#b00}img.thumb{height:140px;margin:4px;border:1px solid #ccc}</style>")


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


def _page(title: str, body: str, head: str = "") -> str:
    return (f"<!DOCTYPE html>\n<html><head><meta charset='utf-8'><title>{html.escape(title)}"
            f"</title>{head}{_STYLE}</head><body>\n<h1>{html.escape(title)}</h1>\n{body}\n"
            "</body></html>\n")


def _link(href: Path | str, text: str) -> str:
    return f"<a href='{html.escape(str(href))}'>{html.escape(text)}</a>"


def _summary(results: Path) -> str:
    """A results.json as a small key/value table (nested values as compact JSON)."""
    try:
        data = json.loads(results.read_text())
    except (OSError, ValueError):
        return "<p><i>no results.json</i></p>"
    if not isinstance(data, dict):
        data = {"results": data}
    rows = "".join(f"<tr><th>{html.escape(str(k))}</th><td>{html.escape(_short(v))}</td></tr>"
                   for k, v in data.items())
    return f"<table>{rows}</table>"


def _short(value: Any, limit: int = 200) -> str:
    text = value if isinstance(value, str) else json.dumps(value, sort_keys=True)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _run_section(run: dict[str, Any], run_dir: Path) -> str:
    name = run["name"]
    status = run["status"]
    cls = "" if status == "ok" else " class='failed'"
    links = [_link(run[k], k) for k in ("notebook", "html") if run.get(k)]
    head = (f"<h2 id='{html.escape(name)}'{cls}>{html.escape(name)} - {html.escape(status)} "
            f"({run['seconds']:.1f} s)</h2>\n<p>{' | '.join(links)}</p>")
    if run.get("error"):
        head += f"<pre class='failed'>{html.escape(run['error'])}</pre>"
    out_dir = run_dir / name
    figures = sorted((out_dir / "figures").glob("*.png")) if out_dir.is_dir() else []
    thumbs = "".join(f"<a href='{html.escape(str(f.relative_to(run_dir)))}'><img class='thumb' "
                     f"src='{html.escape(str(f.relative_to(run_dir)))}' "
                     f"title='{html.escape(f.stem)}'></a>" for f in figures)
    return f"{head}\n{_summary(out_dir / 'results.json')}\n<p>{thumbs}</p>"


def _tables(tables: Sequence[Path], run_dir: Path) -> str:
    import pandas as pd

    parts = []
    for csv in tables:
        try:
            frame = pd.read_csv(csv).to_html(index=False, na_rep="", border=0)
        except (OSError, ValueError) as err:
            frame = f"<p class='failed'>unreadable: {html.escape(str(err))}</p>"
        parts.append(f"<h3>{_link(csv.relative_to(run_dir), csv.name)}</h3>\n{frame}")
    return "\n".join(parts) or "<p><i>no tables</i></p>"


def run_index_html(record: dict[str, Any], run_dir: str | os.PathLike[str],
                   tables: Sequence[Path]) -> str:
    """A run's index page from its record: failures first, then every run and the tables."""
    run_dir = Path(run_dir)
    runs = record["runs"]
    failed = [r for r in runs if r["status"] != "ok"]
    top = (f"<p>mode: {html.escape(record['mode'])}; {len(runs)} runs, {len(failed)} failed; "
           f"total wall time {record['seconds']:.1f} s; "
           f"started {html.escape(record['started'])}</p>")
    if failed:
        items = "".join(f"<li>{_link('#' + r['name'], r['name'])}: {html.escape(r['status'])}</li>"
                        for r in failed)
        top += f"<div class='failed'><b>Failed:</b><ul>{items}</ul></div>"
    if record.get("problems"):
        items = "".join(f"<li>{html.escape(p)}</li>" for p in record["problems"])
        top += f"<div class='failed'><b>Problems:</b><ul>{items}</ul></div>"
    rows = "".join(f"<tr><td>{_link('#' + r['name'], r['name'])}</td><td>{r['status']}</td>"
                   f"<td>{r['seconds']:.1f}</td></tr>" for r in runs)
    top += f"<table><tr><th>run</th><th>status</th><th>wall time [s]</th></tr>{rows}</table>"
    sections = "\n".join(_run_section(r, run_dir) for r in runs)
    return _page(f"alte report {run_dir.name}",
                 f"{top}\n{sections}\n<h2>Tables</h2>\n{_tables(tables, run_dir)}")


def top_index_html(runs: Sequence[tuple[str, dict[str, Any] | None]], latest: str | None) -> str:
    """``reports/index.html``: redirect to the latest run, list all runs (relative paths)."""
    head = (f"<meta http-equiv='refresh' content='0; url={html.escape(latest)}/index.html'>"
            if latest else "")
    items = []
    for rel, record in runs:
        if record is None:
            state = "interrupted (unfinished)"
        else:
            bad = sum(r["status"] != "ok" for r in record["runs"])
            state = f"{record['mode']}, {len(record['runs'])} runs, {bad} failed"
        items.append(f"<li>{_link(rel + '/index.html', rel)} - {html.escape(state)}</li>")
    body = (f"<p>{_link(latest + '/index.html', 'latest report')}</p>" if latest else
            "<p>no finished report yet</p>")
    return _page("alte reports", f"{body}\n<ul>{''.join(items)}</ul>", head)
