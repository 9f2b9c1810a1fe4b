"""Faults: ``alte simulate`` killed mid-write, altered or foreign terrain folders.

A killed run must leave nothing that a later run takes for a finished terrain, and
the next run must complete. (``alte report`` killed mid-way is
tests/lab/report/test_command.py::test_killed_report_leaves_nothing_finished_and_rerun_completes.)
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from alte.paths import REPO_ROOT
from alte.sim.scenario import load_scenario

REPO = REPO_ROOT
TERRAIN = "sim_lan_1"


def _simulate(out: Path, frames: int) -> subprocess.Popen:
    return subprocess.Popen(
        [sys.executable, "-m", "alte", "simulate", TERRAIN, "--frames", str(frames),
         "--out", str(out)],
        cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.PIPE, start_new_session=True)


def _kill_when_writing(proc: subprocess.Popen, out: Path, timeout: float = 120.0) -> bool:
    """SIGKILL ``proc`` as soon as its temporary ``.part`` folder appears; False if it ended."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline and proc.poll() is None:
        if out.is_dir() and any(p.name.endswith(".part") for p in out.iterdir()):
            time.sleep(0.05)  # let it write a little
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
            return True
        time.sleep(0.01)
    proc.kill()
    proc.wait()
    return False


def _finished(out: Path) -> list[Path]:
    return [p for p in out.iterdir() if not p.name.startswith(".")] if out.is_dir() else []


def test_killed_simulate_leaves_no_finished_terrain_and_rerun_completes(bags, capsys, tmp_path):
    out = tmp_path / "data"
    proc = _simulate(out, frames=400)
    if not _kill_when_writing(proc, out):
        pytest.fail(f"alte simulate ended before it could be killed: {proc.stderr.read()[-500:]}")
    assert proc.returncode == -signal.SIGKILL
    assert _finished(out) == []  # only the hidden .part folder is left
    code, said, err = bags.run_cli(capsys, "simulate", TERRAIN, "--frames", "400", "--out", out)
    assert code == 0, err
    assert "(simulated in" in said  # really simulated, not "up to date"
    (folder,) = _finished(out)
    scenario = load_scenario(folder)
    assert scenario.metadata["counts"]["frames"] == 400
    code, said, _ = bags.run_cli(capsys, "simulate", TERRAIN, "--frames", "400", "--out", out)
    assert code == 0 and "(up to date)" in said


def test_altered_terrain_folder_is_simulated_again(bags, capsys, tmp_path):
    out = tmp_path / "data"
    assert bags.run_cli(capsys, "simulate", TERRAIN, "--frames", "2", "--out", out)[0] == 0
    (folder,) = _finished(out)
    db = folder / "bag" / "bag.db3"
    db.write_bytes(db.read_bytes()[: db.stat().st_size // 2])  # e.g. a copy cut short
    code, said, _ = bags.run_cli(capsys, "simulate", TERRAIN, "--frames", "2", "--out", out)
    assert code == 0 and "(simulated in" in said
    assert bags.run_cli(capsys, "info", folder / "bag")[0] == 0


def test_foreign_folder_is_never_overwritten(bags, capsys, tmp_path):
    out = tmp_path / "data"
    assert bags.run_cli(capsys, "simulate", TERRAIN, "--frames", "2", "--out", out)[0] == 0
    (folder,) = _finished(out)
    (folder / "scenario.json").unlink()  # now a folder alte did not finish
    (folder / "mine.txt").write_text("user data")
    code, _, err = bags.run_cli(capsys, "simulate", TERRAIN, "--frames", "2", "--out", out)
    assert code == 2
    line = bags.one_line_error(err, "simulate")
    assert f"{folder} exists but is not a simulated terrain folder" in line
    assert (folder / "mine.txt").read_text() == "user data"


def test_unknown_terrain(bags, capsys, tmp_path):
    code, _, err = bags.run_cli(capsys, "simulate", "sim_nav_9", "--out", tmp_path)
    assert code == 2
    assert "unknown terrain 'sim_nav_9'; valid: sim_nav_1" in bags.one_line_error(err, "simulate")
    assert list(tmp_path.iterdir()) == []
