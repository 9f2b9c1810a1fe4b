"""Row 8: the wall time of ``make report`` and each stage's share, read, never re-run.

The report runner records its total, its CPU seconds (every kernel and worker it
waited for), the load average and every notebook's seconds in
``reports/latest/run.json``; the bench reads that record. The peers: the thesis'
MATLAB mapping time summed over tables 5.7-5.12 (informative only: different
machine, and the thesis times the mappers alone) and the workbench's own budget, a
full report in 10 minutes of wall on a 2-core machine (:data:`BUDGET_S`); on a
shared machine the wall time counts the others' load, so the CPU seconds over the
two cores are shown beside it.
"""

from __future__ import annotations

from pathlib import Path

from alte.lab.studies.thesis.numbers import COMPARISONS, SWEEPS
from alte.types import JSON, JSONDict, JSONMap
from bench.core import Context, Result

__all__ = ["BUDGET_S", "CORES", "report_wall_time", "stage_shares", "thesis_total_s"]

#: A full ``make report`` on a fresh clone of a 2-core machine (bootstrap included).
BUDGET_S = 600.0
#: The cores of that machine (a report's CPU seconds / CORES: its wall on an idle one).
CORES = 2


def thesis_total_s() -> float:
    """Seconds summed over tables 5.7, 5.8, 5.9, 5.12 and the rows 5.10-5.11 repeat."""
    sweeps = sum(row[1] for spec in SWEEPS.values() for row in spec["rows"])
    repeated = sum(SWEEPS[table]["rows"][row][1]
                   for chosen in COMPARISONS.values() for table, row in chosen.values())
    return float(sweeps + repeated)


def _seconds(value: JSON) -> float:
    """A record's seconds (0 when missing)."""
    return float(value) if isinstance(value, int | float) else 0.0


def stage_shares(record: JSONMap) -> dict[str, float]:
    """Each notebook run's share of the report's wall time; the rest is simulation/publishing."""
    from alte.lab.report.runs import record_runs

    total = _seconds(record.get("seconds"))
    runs = {str(r["name"]): _seconds(r.get("seconds")) for r in record_runs(record)}
    if total <= 0:
        return {}
    shares = {name: sec / total for name, sec in runs.items()}
    shares["other (terrains, publishing)"] = max(0.0, 1.0 - sum(shares.values()))
    return shares


def report_wall_time(ctx: Context) -> list[Result]:
    """Row 8 from the latest finished report run, or 'not run' when there is none."""
    from alte.lab.report.runs import read_record, record_runs

    latest = Path(ctx.config.reports_dir) / "latest"
    record = read_record(latest) if latest.is_dir() else None
    peer = thesis_total_s()
    if record is None:
        return [Result(8, "make report (not run: no reports/latest/run.json)", float("nan"),
                       peer, "s", "informative", None, {"status": "not run"})]
    detail: JSONDict = {
        "status": "read", "run": str(latest.resolve()), "mode": record.get("mode"),
        "started": record.get("started"), "shares": stage_shares(record),
        "run_status": {str(r["name"]): r.get("status") for r in record_runs(record)}}
    seconds = _seconds(record.get("seconds"))
    case = f"make report ({record.get('mode')} mode, {record.get('started')})"
    rows = [Result(8, case, seconds or float("nan"), peer, "s", "informative", None, detail)]
    cpu = _seconds(record.get("cpu_s"))
    if cpu > 0:  # recorded since the runner counts its kernels' CPU
        idle = cpu / CORES
        budget: JSONDict = {"cpu_s": cpu, "wall_s": seconds, "idle_wall_s": idle,
                            "load_average": record.get("load_average")}
        full = record.get("mode") == "full"
        rows.append(Result(8, f"{case}: CPU s / {CORES} cores vs the 10-minute budget", idle,
                           BUDGET_S, "s", f"<= {BUDGET_S:.0f} s (full mode)",
                           (idle <= BUDGET_S) if full else None, budget))
    return rows
