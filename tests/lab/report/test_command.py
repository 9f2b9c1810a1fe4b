"""``alte report`` on the command line, including being killed mid-way."""

from __future__ import annotations

import contextlib
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from alte.cli import main
from alte.lab.report.runs import list_runs
from alte.paths import REPO_ROOT

from .conftest import write_plan

ROOT = REPO_ROOT


def _args(tmp_path: Path, notebooks: Path, *extra: str) -> list[str]:
    plan = write_plan(tmp_path / "plan.json", [{"name": "slow", "notebook": "slow.ipynb"},
                                              {"name": "bad", "notebook": "bad.ipynb"}])
    return ["report", "--notebooks", str(notebooks), "--plan", str(plan),
            "--out", str(tmp_path / "reports"), "--data", str(tmp_path / "data"), "--no-warmup",
            *extra]


def test_misspelt_param_is_an_error(tmp_path: Path, notebooks: Path,
                                    capsys: pytest.CaptureFixture[str]) -> None:
    assert main(_args(tmp_path, notebooks, "--param", "SLEEPP=1")) == 2
    err = capsys.readouterr().err
    assert "unknown notebook parameter SLEEPP; valid parameters: MESSAGE, SLEEP" in err
    assert not (tmp_path / "reports").exists()


def test_bad_only_is_an_error(tmp_path: Path, notebooks: Path,
                              capsys: pytest.CaptureFixture[str]) -> None:
    assert main(_args(tmp_path, notebooks, "--only", "slo")) == 2
    assert "--only: run slo: no such run; valid: bad, slow" in capsys.readouterr().err


def test_jobs_must_be_positive(tmp_path: Path, notebooks: Path,
                               capsys: pytest.CaptureFixture[str]) -> None:
    assert main(_args(tmp_path, notebooks, "--jobs", "0")) == 2
    assert "--jobs 0: must be at least 1" in capsys.readouterr().err


def test_missing_plan_file(tmp_path: Path, notebooks: Path,
                           capsys: pytest.CaptureFixture[str]) -> None:
    args = _args(tmp_path, notebooks)
    args[args.index("--plan") + 1] = str(tmp_path / "absent.json")
    assert main(args) == 2
    assert "absent.json" in capsys.readouterr().err


def _wait_for(path_glob: str, folder: Path, proc: subprocess.Popen, timeout: float) -> Path:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        found = sorted(folder.glob(path_glob))
        if found:
            return found[0]
        if proc.poll() is not None:
            raise AssertionError(f"alte report exited early: {proc.communicate()}")
        time.sleep(0.2)
    raise AssertionError(f"{path_glob} did not appear in {timeout} s")


def _kill(pid: int) -> None:
    with contextlib.suppress(ProcessLookupError):
        os.kill(pid, signal.SIGKILL)


@pytest.mark.full
@pytest.mark.slow
def test_killed_report_leaves_nothing_finished_and_rerun_completes(
        tmp_path: Path, notebooks: Path) -> None:
    reports = tmp_path / "reports"
    cmd = [sys.executable, "-m", "alte", *_args(tmp_path, notebooks, "--only", "slow")]
    proc = subprocess.Popen([*cmd, "--param", "SLEEP=120"], cwd=ROOT, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, start_new_session=True)
    try:
        pid_file = _wait_for("runs/*/slow/kernel.pid", reports, proc, timeout=120)
        time.sleep(0.5)  # papermill saves the partial notebook after the executed cells
    finally:
        _kill(proc.pid)
        proc.communicate()
    _kill(int(pid_file.read_text()))  # the kernel lives in its own session
    killed = pid_file.parents[1]
    names = sorted(p.name for p in killed.iterdir())
    assert ".slow.part.ipynb" in names  # the partial notebook, under its temporary name
    assert not {"slow.ipynb", "slow.failed.ipynb", "run.json", "index.html"} & set(names)
    assert not (killed / "slow" / "results.json").exists()
    assert not (reports / "latest").exists()
    assert [i.finished for i in list_runs(reports)] == [False]

    done = subprocess.run([*cmd, "--param", "SLEEP=0"], cwd=ROOT, capture_output=True,
                          text=True, timeout=300, check=False)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "1/1 notebooks ok" in done.stdout
    latest = (reports / "latest").resolve()
    assert latest != killed.resolve()
    assert json.loads((latest / "run.json").read_text())["runs"][0]["status"] == "ok"
    assert (latest / "slow.ipynb").exists() and (latest / "slow" / "results.json").exists()
    assert "interrupted (unfinished)" in (reports / "index.html").read_text()


@pytest.mark.slow
def test_failed_notebook_exit_code(tmp_path: Path, notebooks: Path,
                                   capsys: pytest.CaptureFixture[str]) -> None:
    assert main(_args(tmp_path, notebooks, "--only", "bad")) == 1
    out = capsys.readouterr().out
    assert "failed" in out and "FAILED: bad" in out and "0/1 notebooks ok" in out
    assert (tmp_path / "reports" / "latest" / "bad.failed.ipynb").exists()
