"""Run folders, the ``latest`` link, run records and table publishing."""

from __future__ import annotations

import os
from datetime import UTC, datetime
from pathlib import Path

import pytest

from alte.errors import AlteError, ReportError
from alte.lab.report.runs import (
    list_runs,
    new_run_dir,
    point_latest,
    publish_tables,
    read_record,
    write_record,
)

NOW = datetime(2024, 5, 6, 7, 8, 9, tzinfo=UTC)


def test_new_run_dir_never_reuses(tmp_path: Path) -> None:
    first = new_run_dir(tmp_path, NOW)
    (first / "keep.txt").write_text("old")
    second = new_run_dir(tmp_path, NOW)
    assert first.name == "20240506T070809Z" and second.name == "20240506T070809Z-1"
    assert (first / "keep.txt").read_text() == "old"
    assert list(second.iterdir()) == []


def test_point_latest_is_relative_and_repointed(tmp_path: Path) -> None:
    a, b = new_run_dir(tmp_path, NOW), new_run_dir(tmp_path, NOW)
    link = point_latest(tmp_path, a)
    assert os.readlink(link) == "runs/20240506T070809Z"
    point_latest(tmp_path, b)
    assert link.resolve() == b.resolve()
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".latest")] == []


def test_point_latest_refuses_a_real_folder(tmp_path: Path) -> None:
    (tmp_path / "latest").mkdir()
    with pytest.raises(ReportError, match="latest exists and is not a symlink"):
        point_latest(tmp_path, new_run_dir(tmp_path, NOW))


def test_record_marks_finished_once(tmp_path: Path) -> None:
    run = new_run_dir(tmp_path, NOW)
    assert read_record(run) is None
    write_record(run, {"mode": "quick", "path": Path("x")})
    assert read_record(run) == {"mode": "quick", "path": "x"}
    with pytest.raises(AlteError, match=r"run\.json already exists"):
        write_record(run, {"mode": "full"})


def test_corrupt_record(tmp_path: Path) -> None:
    run = new_run_dir(tmp_path, NOW)
    (run / "run.json").write_text("{")
    with pytest.raises(ReportError, match=r"run\.json: corrupt run record"):
        read_record(run)


def test_list_runs_newest_first_with_unfinished(tmp_path: Path) -> None:
    assert list_runs(tmp_path) == []
    old = new_run_dir(tmp_path, NOW)
    write_record(old, {"mode": "quick"})
    new = new_run_dir(tmp_path, datetime(2025, 1, 1, tzinfo=UTC))
    infos = list_runs(tmp_path)
    assert [i.path for i in infos] == [new, old]
    assert [i.finished for i in infos] == [False, True]


def test_publish_tables_copies_bytes(tmp_path: Path) -> None:
    source = tmp_path / "run" / "tables"
    source.mkdir(parents=True)
    (source / "table_5_1.csv").write_bytes(b"a,b\n1,2\n")
    (source / "notes.txt").write_text("not a table")
    (tmp_path / "tables").mkdir()
    (tmp_path / "tables" / "table_5_1.csv").write_text("stale")
    assert publish_tables(source, tmp_path) == [tmp_path / "tables" / "table_5_1.csv"]
    assert (tmp_path / "tables" / "table_5_1.csv").read_bytes() == b"a,b\n1,2\n"
    assert sorted(p.name for p in (tmp_path / "tables").iterdir()) == ["table_5_1.csv"]
    assert publish_tables(tmp_path / "absent", tmp_path) == []
