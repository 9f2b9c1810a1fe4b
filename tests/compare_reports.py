"""Compare the tables of two report runs, wall-clock columns aside (a refactor's check).

    python tests/compare_reports.py BEFORE/tables AFTER/tables

Prints the tables identical once the time columns are dropped, and for every other table
the columns that differ and, where a table has rows per metric or reading, which ones: a
behaviour-preserving change differs in time readings only (times, the evidence quoting
them, table 5.10's pick by the thesis' time-weighted rule). Exit status 1 when a table
differs outside them.
"""

from __future__ import annotations

import sys
from pathlib import Path

import pandas as pd

#: Parts of a column name that mark a wall-clock or CPU-time column.
TIME_MARKS = ("elapsed", "map_cpu", "wall_s", "cpu_s", "time_repeats", "rule_score",
              "ms_per_scan", "seconds", "latency", "time per scan", "CPU per scan", "map_s",
              "build_s", "search_s")
#: Columns naming what a row reads, and the words of a time reading there.
ROW_KEYS, TIME_ROWS = ("metric", "what"), ("elapsed", "cpu", "time")
#: Tables whose content follows a pick made on times (any column), or quotes times (those
#: columns only).
TIME_TABLES: dict[str, set[str] | None] = {"table_5_10.csv": None, "table_5_11.csv": None,
                                           "claims.csv": {"evidence"}}


def _is_time(column: str) -> bool:
    return not column.startswith("thesis_") and any(m in column for m in TIME_MARKS)


def _time_rows_only(a: pd.DataFrame, b: pd.DataFrame, cols: list[str]) -> bool:
    """True when the rows that differ are all time readings."""
    key = next((k for k in ROW_KEYS if k in a.columns), None)
    if key is None or len(a) != len(b):
        return False
    equal = a[cols].eq(b[cols]) | (a[cols].isna() & b[cols].isna())
    differs = ~equal.all(axis=1)
    return bool(a.loc[differs, key].astype(str).str.lower().str.contains("|".join(TIME_ROWS)).all())


def compare(before: Path, after: Path) -> int:
    names = sorted({p.name for p in before.glob("*.csv")} | {p.name for p in after.glob("*.csv")})
    same, bad = [], 0
    for name in names:
        if not (before / name).is_file() or not (after / name).is_file():
            print(f"DIFFER {name}: in one run only")
            bad += 1
            continue
        a, b = pd.read_csv(before / name), pd.read_csv(after / name)
        cols = [c for c in a.columns if not _is_time(c)]
        if list(a.columns) != list(b.columns):
            print(f"DIFFER {name}: columns {sorted(set(a.columns) ^ set(b.columns))}")
            bad += 1
        elif a[cols].equals(b[cols]):
            same.append(name)
        else:
            changed = [c for c in cols if not a[c].equals(b[c])]
            allowed = TIME_TABLES.get(name, set())
            timed = (allowed is None or (bool(allowed) and set(changed) <= allowed)
                     or _time_rows_only(a, b, cols))
            print(f"{'time readings' if timed else 'DIFFER'} {name}: {', '.join(changed)}")
            bad += not timed
    print(f"{len(same)} of {len(names)} tables identical, time columns aside: {', '.join(same)}")
    return 1 if bad else 0


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit("usage: python tests/compare_reports.py BEFORE/tables AFTER/tables")
    sys.exit(compare(Path(sys.argv[1]), Path(sys.argv[2])))
