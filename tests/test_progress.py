"""Progress bars reach the terminal of ``alte report`` from its notebook kernels."""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest
from report.conftest import make_notebook

from alte import progress
from alte.lab.report.plan import Entry, build_plan
from alte.lab.report.runner import run_report


@pytest.fixture
def fresh_stream(monkeypatch):
    """:func:`progress.report_stream` read again from the environment this test sets."""
    progress.report_stream.cache_clear()
    yield monkeypatch
    progress.report_stream.cache_clear()


def test_a_kernels_bar_writes_short_lines_to_the_relay(fresh_stream) -> None:
    shown: list[str] = []
    with progress.Relay(shown.append):
        progress.report_stream.cache_clear()
        with progress.bar(total=4, desc="sweep runs", unit="run") as bar:
            for _ in range(4):
                bar.update()
        assert list(progress.bar(range(3), desc="sensor missions")) == [0, 1, 2]
        progress.report_stream().stream.close()  # as a kernel's exit does
    assert os.environ.get(progress.ENV) is None  # set only while the relay is open
    assert shown[0].startswith("sweep runs 0/4 [00:00<")
    assert any(line.startswith("sweep runs 4/4 [") for line in shown)
    assert shown[-1].startswith("sensor missions 3/3 [")


def test_bar_without_a_report_is_tqdms_own(tmp_path, fresh_stream, capsys) -> None:
    fresh_stream.delenv(progress.ENV, raising=False)
    assert progress.report_stream() is None
    assert list(progress.bar(range(2), desc="maps")) == [0, 1]
    assert "maps: 100%" in capsys.readouterr().err
    progress.report_stream.cache_clear()
    fresh_stream.setenv(progress.ENV, str(tmp_path / "missing" / "log"))
    assert progress.report_stream() is None  # a target that does not open: tqdm's own


def test_a_log_gets_a_line_per_bar_every_interval_and_the_last() -> None:
    written: list[str] = []
    throttle = progress.Throttle(written.append, every=3600)
    for line in ("sweep runs 0/9 [00:00<?]", "sweep runs 1/9 [00:01<00:08]",
                 "sensor missions 0/2 [00:00<?]", "sweep runs 9/9 [00:09<00:00]"):
        throttle(line)
    assert written == ["sweep runs 0/9 [00:00<?]", "sensor missions 0/2 [00:00<?]",
                       "sweep runs 9/9 [00:09<00:00]"]


def test_report_kernels_draw_on_the_report_stderr(tmp_path: Path, capfd) -> None:
    """A notebook's bar reaches the stderr of the process running the report, and stays
    out of the executed notebook."""
    body = ("from alte.progress import bar\n"
            "for _ in bar(range(5), desc='fake missions', unit='mission'):\n    pass\n")
    make_notebook(tmp_path / "nb" / "slow.ipynb", 'OUT_DIR = "reports/scratch/slow"\n', body)
    runs = build_plan((Entry("slow", "slow.ipynb"),), quick=True, notebooks_dir=tmp_path / "nb")
    report = run_report(runs, tmp_path / "reports", tmp_path / "data", quick=True,
                        progress=True, cwd=tmp_path)
    assert [r.status for r in report.results] == ["ok"]
    assert "fake missions 5/5 [" in capfd.readouterr().err
    executed = json.loads((report.run_dir / "slow.ipynb").read_text())
    outputs = [c.get("outputs", []) for c in executed["cells"]]
    assert "fake missions" not in json.dumps(outputs)
