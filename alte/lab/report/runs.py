"""Run folders: ``reports/runs/<UTC stamp>/``, a ``latest`` link and the run record.

A run folder is claimed with ``mkdir`` (never reused), a run counts as finished
only once its ``run.json`` exists (written last, atomically), and ``latest`` is
repointed by renaming a temporary symlink over it, so a killed run can never be
mistaken for a finished one and never hides the previous report.
"""

from __future__ import annotations

import json
import os
import shutil
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path

from alte.errors import ReportError
from alte.fsutil import atomic_path
from alte.types import JSONDict, JSONMap

__all__ = [
    "RUN_RECORD",
    "RunInfo",
    "list_runs",
    "new_run_dir",
    "point_latest",
    "publish_tables",
    "read_record",
    "record_runs",
    "write_record",
]

#: The file whose presence marks a finished run folder.
RUN_RECORD = "run.json"


@dataclass(frozen=True)
class RunInfo:
    """A run folder and its record (``None`` when the run never finished)."""

    path: Path
    record: JSONDict | None

    @property
    def finished(self) -> bool:
        """True when the run wrote its record."""
        return self.record is not None


def new_run_dir(reports: str | os.PathLike[str], now: datetime | None = None) -> Path:
    """Create and return a fresh ``reports/runs/<stamp>[-k]`` folder."""
    runs = Path(reports) / "runs"
    runs.mkdir(parents=True, exist_ok=True)
    stamp = (now or datetime.now(UTC)).strftime("%Y%m%dT%H%M%SZ")
    for k in range(1000):
        path = runs / (stamp if k == 0 else f"{stamp}-{k}")
        try:
            path.mkdir()
        except FileExistsError:
            continue
        return path
    raise ReportError(f"{runs}: cannot create a new run folder for {stamp}")


def point_latest(reports: str | os.PathLike[str], run_dir: str | os.PathLike[str]) -> Path:
    """Atomically make ``reports/latest`` a relative symlink to ``run_dir``."""
    reports = Path(reports)
    link = reports / "latest"
    if link.exists() and not link.is_symlink():
        raise ReportError(f"{link} exists and is not a symlink; remove it to publish reports")
    tmp = reports / f".latest.{os.getpid()}.part"
    tmp.unlink(missing_ok=True)
    os.symlink(os.path.relpath(Path(run_dir).resolve(), reports.resolve()), tmp)
    os.replace(tmp, link)
    return link


def write_record(run_dir: str | os.PathLike[str], record: JSONMap) -> Path:
    """Write ``run.json`` (atomically, once): the run is finished from then on."""
    path = Path(run_dir) / RUN_RECORD
    with atomic_path(path) as tmp:
        tmp.write_text(json.dumps(record, indent=2, sort_keys=True, default=str) + "\n")
        tmp.chmod(0o644)
    return path


def read_record(run_dir: str | os.PathLike[str]) -> JSONDict | None:
    """The run's record, or ``None`` for a run that did not finish."""
    path = Path(run_dir) / RUN_RECORD
    try:
        record: JSONDict = json.loads(path.read_text())
        return record
    except FileNotFoundError:
        return None
    except ValueError as err:
        raise ReportError(f"{path}: corrupt run record ({err})") from err


def record_runs(record: JSONMap) -> list[JSONMap]:
    """The notebook runs of a run record (its ``runs``: one object per notebook)."""
    runs = record.get("runs", [])
    if isinstance(runs, str) or not isinstance(runs, Sequence):
        return []
    return [r for r in runs if isinstance(r, Mapping)]


def list_runs(reports: str | os.PathLike[str]) -> list[RunInfo]:
    """Every run folder under ``reports/runs``, newest first."""
    runs = Path(reports) / "runs"
    if not runs.is_dir():
        return []
    folders = sorted((p for p in runs.iterdir() if p.is_dir() and not p.name.startswith(".")),
                     key=lambda p: p.name, reverse=True)
    return [RunInfo(p, read_record(p)) for p in folders]


def publish_tables(tables_dir: str | os.PathLike[str],
                   reports: str | os.PathLike[str]) -> list[Path]:
    """Copy every CSV of ``tables_dir`` to ``reports/tables/`` (atomic, byte for byte)."""
    source = Path(tables_dir)
    published = []
    for csv in sorted(source.glob("*.csv")) if source.is_dir() else []:
        target = Path(reports) / "tables" / csv.name
        with atomic_path(target, overwrite=True) as tmp:
            shutil.copyfile(csv, tmp)
            tmp.chmod(0o644)
        published.append(target)
    return published
