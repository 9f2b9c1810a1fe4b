"""Executing fake notebooks: failure isolation, run folders, latest, determinism."""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

import pytest

from alte.errors import ReportError, SimulationError
from alte.lab.report.plan import Entry, Run, build_plan
from alte.lab.report.runner import (
    THREAD_VARIABLES,
    ensure_terrains,
    execute_run,
    kernel_threads,
    run_report,
)

from .conftest import BAD_BODY, BAD_PARAMS, GOOD_BODY, GOOD_PARAMS, make_notebook

ENTRIES = (Entry("good", "good.ipynb"), Entry("bad", "bad.ipynb"))


@pytest.fixture(scope="module")
def two_reports(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Any, Any]:
    """The same good+bad plan reported twice into one reports folder."""
    root = tmp_path_factory.mktemp("report")
    make_notebook(root / "nb" / "good.ipynb", GOOD_PARAMS, GOOD_BODY)
    make_notebook(root / "nb" / "bad.ipynb", BAD_PARAMS, BAD_BODY)
    runs = build_plan(ENTRIES, quick=True, notebooks_dir=root / "nb")
    first = run_report(runs, root / "reports", root / "data", quick=True, progress=False)
    (first.run_dir / "marker.txt").write_text("first")
    second = run_report(runs, root / "reports", root / "data", quick=True, progress=False,
                        jobs=2)
    return root / "reports", first, second


@pytest.mark.slow
def test_failure_is_isolated(two_reports: tuple[Path, Any, Any]) -> None:
    _, first, _ = two_reports
    assert [(r.name, r.status) for r in first.results] == [("good", "ok"), ("bad", "failed")]
    assert [r.name for r in first.failed] == ["bad"]
    assert first.results[1].error == "cell 3: ValueError: boom"
    run = first.run_dir
    assert (run / "good" / "results.json").exists()
    assert (run / "good" / "figures" / "curve.png").stat().st_size > 0
    partial = json.loads((run / "bad.failed.ipynb").read_text())
    outputs = [o for c in partial["cells"] for o in c.get("outputs", [])]
    assert any("before the failure" in "".join(o.get("text", "")) for o in outputs)
    assert not (run / "bad.ipynb").exists() and not (run / "bad" / "results.json").exists()
    assert (run / "good.html").exists() and (run / "bad.failed.html").exists()
    assert [p.name for p in run.iterdir() if p.name.endswith((".part", ".part.ipynb"))] == []


@pytest.mark.slow
def test_record_and_index(two_reports: tuple[Path, Any, Any]) -> None:
    _, first, second = two_reports
    record = json.loads((first.run_dir / "run.json").read_text())
    assert record["mode"] == "quick" and record["tables"] == ["table_5_1.csv"]
    assert record["runs"][0]["parameters"]["OUT_DIR"] == str(first.run_dir / "good")
    assert record["runs"][0]["parameters"]["TABLES_DIR"] == str(first.run_dir / "tables")
    page = (first.run_dir / "index.html").read_text()
    assert '<a href="#bad">bad</a>: failed' in page and "table_5_1.csv" in page
    # CPU seconds: each kernel's when the runs did not overlap, the whole report's always
    assert all(r["cpu_s"] > 0 for r in record["runs"])
    assert record["cpu_s"] >= sum(r["cpu_s"] for r in record["runs"])
    assert set(record["load_average"]) == {"start", "end"}
    again = json.loads((second.run_dir / "run.json").read_text())
    assert [r["cpu_s"] for r in again["runs"]] == [None, None] and again["cpu_s"] > 0


@pytest.mark.slow
def test_kernels_side_by_side_get_their_share_of_the_cores(
        two_reports: tuple[Path, Any, Any]) -> None:
    """One job: every core for its kernel's thread pools; two: half each (what the user
    set stays)."""
    _, first, second = two_reports
    cores = os.cpu_count() or 1
    for report, share in ((first, cores), (second, max(1, cores // 2))):
        seen = json.loads((report.run_dir / "good" / "threads.json").read_text())
        assert seen == {n: os.environ.get(n, str(share)) for n in THREAD_VARIABLES}


def test_kernel_threads_sets_only_what_the_user_left_unset(
        monkeypatch: pytest.MonkeyPatch) -> None:
    for name in THREAD_VARIABLES:
        monkeypatch.delenv(name, raising=False)
    monkeypatch.setenv("OMP_NUM_THREADS", "3")
    monkeypatch.setattr(os, "cpu_count", lambda: 8)
    with kernel_threads(4) as given:
        assert given == {n: "2" for n in THREAD_VARIABLES if n != "OMP_NUM_THREADS"}
        assert os.environ["OPENBLAS_NUM_THREADS"] == "2" and os.environ["OMP_NUM_THREADS"] == "3"
    assert os.environ["OMP_NUM_THREADS"] == "3"
    assert not {n for n in THREAD_VARIABLES if n != "OMP_NUM_THREADS"} & set(os.environ)
    with kernel_threads(16) as given:
        assert set(given.values()) == {"1"}


@pytest.mark.slow
def test_new_run_never_destroys_previous(two_reports: tuple[Path, Any, Any]) -> None:
    reports, first, second = two_reports
    assert first.run_dir != second.run_dir
    assert (first.run_dir / "marker.txt").read_text() == "first"
    assert (first.run_dir / "good.ipynb").exists() and (first.run_dir / "run.json").exists()
    assert (reports / "latest").resolve() == second.run_dir.resolve()
    top = (reports / "index.html").read_text()
    assert f"runs/{first.run_dir.name}/index.html" in top
    assert f"runs/{second.run_dir.name}/index.html" in top


@pytest.mark.slow
def test_tables_published_and_deterministic(two_reports: tuple[Path, Any, Any]) -> None:
    reports, first, second = two_reports
    a = (first.run_dir / "tables" / "table_5_1.csv").read_bytes()
    b = (second.run_dir / "tables" / "table_5_1.csv").read_bytes()
    assert a == b and a.startswith(b"a,b\n") and a.count(b"\n") == 4
    assert (reports / "tables" / "table_5_1.csv").read_bytes() == a


def _run(name: str, terrains: tuple[str, ...], **params: Any) -> Run:
    return Run(name, Path(f"/nonexistent/{name}.ipynb"), params, {"OUT_DIR": "o", "FRAMES": 10},
               terrains)


def test_ensure_terrains_frames_and_errors(tmp_path: Path) -> None:
    calls = []

    def ensure(name: str, **kwargs: Any) -> None:
        calls.append((name, kwargs))
        if name == "exp_lan_2":
            raise SimulationError("exp_lan_2: broken scene")
        if name == "sim_lan_2":
            raise TypeError("bug in the simulator")

    runs = [_run("a", ("sim_nav_1",), FRAMES=40, SEED=7), _run("b", ("sim_nav_1", "exp_lan_2")),
            _run("c", ("sim_lan_1",), FRAMES=None, SEED=1), _run("d", ("sim_lan_1",), FRAMES=0,
                                                                   SEED=2),
            _run("e", ("sim_lan_2",))]
    errors = ensure_terrains(runs, tmp_path, ensure, seed=3, progress=False)
    assert errors == {"exp_lan_2": "terrain exp_lan_2: exp_lan_2: broken scene",
                      "sim_lan_2": "terrain sim_lan_2: TypeError: bug in the simulator"}
    assert calls == [("sim_nav_1", {"out_dir": tmp_path, "seed": 7, "frames": 40}),
                     ("exp_lan_2", {"out_dir": tmp_path, "seed": 3, "frames": 10}),
                     ("sim_lan_1", {"out_dir": tmp_path, "seed": 3, "frames": None}),
                     ("sim_lan_2", {"out_dir": tmp_path, "seed": 3, "frames": 10})]
    assert ensure_terrains([_run("e", ())], tmp_path, None, progress=False) == {}


def test_missing_terrain_skips_its_runs(tmp_path: Path) -> None:
    def ensure(name: str, **_: Any) -> None:
        raise SimulationError(f"unknown terrain {name!r}")

    report = run_report([_run("a", ("nope",))], tmp_path / "reports", tmp_path / "data",
                        quick=True, ensure=ensure, progress=False)
    assert [(r.name, r.status) for r in report.results] == [("a", "skipped")]
    assert report.problems == ["terrain nope: unknown terrain 'nope'"]
    assert "unknown terrain" in (report.run_dir / "index.html").read_text()
    assert (tmp_path / "reports" / "latest").resolve() == report.run_dir.resolve()


def test_unreadable_notebook_is_a_failure_not_a_crash(tmp_path: Path) -> None:
    result = execute_run(_run("a", ()), tmp_path, tmp_path)
    assert result.status == "failed" and result.notebook is None
    assert "FileNotFoundError" in result.error
    assert os.listdir(tmp_path) == []


def test_runs_marked_first_start_first_and_keep_their_place(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Notebooks start in the plan's order, those marked ``first`` before the rest; the
    record lists them in the plan's order whatever order they ran in."""
    from alte.lab.report import runner
    from alte.lab.report.runner import RunResult

    started: list[str] = []

    def fake(run: Run, *_: object) -> RunResult:
        started.append(run.name)
        return RunResult(run.name, "ok")

    monkeypatch.setattr(runner, "execute_run", fake)
    runs = [Run(name, Path(f"{name}.ipynb"), first=name == "long") for name in ("a", "long", "b")]
    report = run_report(runs, tmp_path / "reports", tmp_path / "data", quick=True,
                        progress=False)
    assert started == ["long", "a", "b"]
    assert [r.name for r in report.results] == ["a", "long", "b"]


def test_empty_plan(tmp_path: Path) -> None:
    with pytest.raises(ReportError, match="nothing to run"):
        run_report([], tmp_path, tmp_path, quick=True)
