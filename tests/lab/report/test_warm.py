"""The report's warmup: started before the terrains, finished before the first notebook."""

from __future__ import annotations

import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from alte.cli import main
from alte.lab.report import runner, warm
from alte.lab.report.plan import Run
from alte.lab.report.runner import RunResult, run_report


def test_warmup_runs_beside_the_terrains_and_before_the_notebooks(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    events = []

    def warmup(progress: bool) -> Callable[[], str | None]:
        events.append("warmup started")
        return lambda: events.append("warmup done") or "kernel warmup failed: boom"

    def execute(run: Run, *_: Any) -> RunResult:
        events.append(f"notebook {run.name}")
        return RunResult(run.name, "ok")

    monkeypatch.setattr(runner, "execute_run", execute)
    run = Run("a", Path("/nonexistent/a.ipynb"), {}, {"OUT_DIR": "o"}, ("t",))
    report = run_report([run], tmp_path / "reports", tmp_path / "data", quick=True,
                        ensure=lambda name, **_: events.append(f"terrain {name}"),
                        progress=False, warmup=warmup)
    assert events == ["warmup started", "terrain t", "warmup done", "notebook a"]
    assert report.problems == ["kernel warmup failed: boom"]


def test_a_failed_warmup_is_reported(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(warm, "COMMAND", (sys.executable, "-c", "print('no numba'); exit(3)"))
    assert warm.start_warmup(progress=False)() == (
        "kernel warmup (alte warmup) failed with exit code 3: no numba")
    monkeypatch.setattr(warm, "COMMAND", (sys.executable, "-c", "pass"))
    assert warm.start_warmup(progress=True)() is None


@pytest.mark.parametrize(("flag", "warms"), [((), True), (("--no-warmup",), False)])
def test_alte_report_warms_first(monkeypatch: pytest.MonkeyPatch, tmp_path: Path,
                                 flag: tuple[str, ...], warms: bool) -> None:
    seen = {}

    def fake(runs: Any, *_: Any, **kwargs: Any) -> Any:
        seen.update(kwargs)
        raise SystemExit(0)

    monkeypatch.setattr("alte.commands.report.run_report", fake)
    with pytest.raises(SystemExit):
        main(["report", "--quick", "--only", "ch2_test_benchmark", "--out", str(tmp_path),
              *flag])
    assert (seen["warmup"] is warm.start_warmup) is warms
