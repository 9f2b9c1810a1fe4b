"""The report runner behind ``alte report``: plan, execute, render, publish."""

from alte.lab.report.html import notebook_to_html, run_index_html, top_index_html
from alte.lab.report.plan import PLAN, TERRAINS, Entry, Run, build_plan, load_plan, parse_param
from alte.lab.report.runner import Report, RunResult, ensure_terrains, execute_run, run_report
from alte.lab.report.runs import list_runs, new_run_dir, point_latest, publish_tables

__all__ = [
    "PLAN",
    "TERRAINS",
    "Entry",
    "Report",
    "Run",
    "RunResult",
    "build_plan",
    "ensure_terrains",
    "execute_run",
    "list_runs",
    "load_plan",
    "new_run_dir",
    "notebook_to_html",
    "parse_param",
    "point_latest",
    "publish_tables",
    "run_index_html",
    "run_report",
    "top_index_html",
]
