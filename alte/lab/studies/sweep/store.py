"""Sweep results as a Parquet dataset: one file per finished run, written atomically.

Each run's row goes to ``OUT/run-<run id>.parquet`` through a temporary name and a
rename (:func:`alte.fsutil.atomic_path`), so a killed sweep loses only the runs
that had not finished; the file names are the resume state (:func:`finished_ids`).
Temporary files start with a dot, which pyarrow's dataset readers ignore.
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Mapping
from pathlib import Path

import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq

from alte.errors import AlteError
from alte.fsutil import atomic_path

__all__ = ["KEY_COLUMNS", "TIMING_COLUMNS", "finished_ids", "load_results", "row_table",
           "write_row"]

#: Columns identifying a run (then ``p_<param>`` columns, then the metrics).
KEY_COLUMNS = ("run_id", "terrain", "frames_requested", "seed", "mapper", "params_json")
#: Timing columns: the only ones that differ between repeated runs (the map's time and
#: its spreads, :class:`alte.metrics.timing.Timing`; the whole run's wall and CPU seconds).
TIMING_COLUMNS = ("elapsed_s", "elapsed_spread", "map_cpu_s", "map_cpu_spread", "wall_s",
                  "cpu_s")

#: Values of columns added later, for rows stored before them.
FILLED = {"poses": "recorded"}

_PREFIX, _SUFFIX = "run-", ".parquet"


def _part(out: Path, run_id: str) -> Path:
    return out / f"{_PREFIX}{run_id}{_SUFFIX}"


def row_table(row: Mapping[str, object]) -> pa.Table:
    """One run's row as the one-row table its file holds."""
    return pa.Table.from_pylist([dict(row)])


def write_row(out: str | os.PathLike[str], row: Mapping[str, object] | pa.Table) -> Path:
    """Write one run's row (or its :func:`row_table`) to its own Parquet file in ``out``
    (atomic; never overwrites)."""
    table = row if isinstance(row, pa.Table) else row_table(row)
    path = _part(Path(out), str(table.column("run_id")[0]))
    with atomic_path(path) as tmp:
        pq.write_table(table, tmp)
    return path


def _files(out: Path) -> list[Path]:
    if out.exists() and not out.is_dir():
        raise AlteError(f"sweep output {out} is a file, not a Parquet dataset folder")
    return sorted(out.glob(f"{_PREFIX}*{_SUFFIX}")) if out.is_dir() else []


def finished_ids(out: str | os.PathLike[str]) -> set[str]:
    """Run ids already stored in ``out`` (empty when the folder does not exist)."""
    return {p.name[len(_PREFIX):-len(_SUFFIX)] for p in _files(Path(out))}


def _read(path: Path) -> pa.Table:
    try:
        with pq.ParquetFile(path) as file:  # no dataset discovery: ~2x read_table's speed
            return file.read()
    except (OSError, pa.ArrowInvalid) as err:
        raise AlteError(f"sweep result {path} is unreadable ({err}); delete it to rerun "
                        "that run") from err


def _ordered_columns(columns: Iterable[str]) -> list[str]:
    cols = list(columns)
    params = sorted(c for c in cols if c.startswith("p_"))
    rest = [c for c in cols if c not in KEY_COLUMNS and c not in params
            and c not in TIMING_COLUMNS]
    return ([c for c in KEY_COLUMNS if c in cols] + params + rest
            + [c for c in TIMING_COLUMNS if c in cols])


def load_results(out: str | os.PathLike[str], order: Iterable[str] | None = None, *,
                 known: Mapping[str, pa.Table] | None = None) -> pd.DataFrame:
    """All rows stored in ``out`` as one table (columns unified across mappers).

    With ``order`` (run ids, e.g. a spec's grid order) only those runs are returned,
    in that order; otherwise every row, sorted by run id. Either way deterministic.
    ``known``: run id -> the :func:`row_table` this process wrote to ``out``, used
    instead of reading its file back (the same table; a sweep's thousands of files
    took seconds to read).
    """
    files = _files(Path(out))
    if not files:
        return pd.DataFrame(columns=list(KEY_COLUMNS))
    known = known or {}
    tables = [known.get(p.name[len(_PREFIX):-len(_SUFFIX)]) for p in files]
    table = pa.concat_tables([t if t is not None else _read(p) for t, p in zip(tables, files,
                                                                                strict=True)],
                             promote_options="permissive")
    frame: pd.DataFrame = table.to_pandas(types_mapper={pa.int64(): pd.Int64Dtype()}.get)
    frame = frame[_ordered_columns(frame.columns)]
    for column, value in FILLED.items():
        if column in frame:
            frame[column] = frame[column].fillna(value)
    if order is None:
        return frame.sort_values("run_id", kind="stable").reset_index(drop=True)
    rank = {run_id: i for i, run_id in enumerate(order)}
    frame = frame[frame["run_id"].isin(rank)]
    return frame.iloc[frame["run_id"].map(rank).argsort(kind="stable")].reset_index(drop=True)
