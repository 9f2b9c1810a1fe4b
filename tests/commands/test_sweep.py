"""``alte sweep``: serial run, resume, overrides, failures and one-line errors."""

from __future__ import annotations

import pytest

from alte.cli import main
from alte.lab.studies.sweep import groups as sweep_groups
from alte.lab.studies.sweep import load_results

SPEC = """\
name: cli
terrains: [sim_lan_1]
frames: 6
data_dir: {data}
output: {out}
truth: {{n_samples: 2000}}
mappers:
  alte2d:
    grid: {{kappa: [0.1, 1.0], max_res: [3]}}
  quadtree:
    rows: [{{max_points: 300}}]
"""


@pytest.fixture
def spec_file(tmp_path):
    path = tmp_path / "cli.yaml"
    path.write_text(SPEC.format(data=tmp_path / "data", out=tmp_path / "runs"))
    return path


def test_sweep_runs_then_resumes(spec_file, tmp_path, capsys):
    argv = ["sweep", str(spec_file), "--scheduler", "serial", "--no-progress"]
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert f"sweep cli: 3 run, 0 already done, 0 failed; 3 rows in {tmp_path / 'runs'}" in out
    assert main(argv) == 0
    assert "0 run, 3 already done" in capsys.readouterr().out
    table = load_results(tmp_path / "runs")
    assert sorted(table["mapper"]) == ["alte2d", "alte2d", "quadtree"]


def test_overrides_frames_out_and_data(spec_file, tmp_path, capsys):
    assert main(["sweep", str(spec_file), "--scheduler", "none", "--no-progress", "--frames",
                 "3", "--out", str(tmp_path / "other"), "--data", str(tmp_path / "d2")]) == 0
    assert "3 rows in" in capsys.readouterr().out
    assert (tmp_path / "d2" / "sim_lan_1-3f").is_dir()
    assert load_results(tmp_path / "other")["frames"].eq(3).all()


def test_seeds_override(spec_file, tmp_path, capsys):
    argv = ["sweep", str(spec_file), "--scheduler", "serial", "--no-progress", "--frames", "3",
            "--seeds", "1", "2"]
    assert main(argv) == 0
    assert "6 rows in" in capsys.readouterr().out
    assert sorted(set(load_results(tmp_path / "runs")["seed"])) == [1, 2]
    assert (tmp_path / "data" / "sim_lan_1-3f-s2").is_dir()


def test_failed_runs_exit_1(spec_file, capsys, monkeypatch):
    def broken(*args, **kwargs):
        raise RuntimeError("mapper crashed")

    monkeypatch.setattr(sweep_groups, "timed_run", broken)
    assert main(["sweep", str(spec_file), "--scheduler", "serial", "--no-progress"]) == 1
    out = capsys.readouterr().out
    assert "failed: sim_lan_1 quadtree {'max_points': 300}: RuntimeError: mapper crashed" in out
    assert "0 run, 0 already done, 3 failed" in out


def test_evidence_is_not_written_while_runs_fail(spec_file, tmp_path, capsys, monkeypatch):
    def broken(*args, **kwargs):
        raise RuntimeError("mapper crashed")

    monkeypatch.setattr(sweep_groups, "timed_run", broken)
    folder = tmp_path / "evidence"
    assert main(["sweep", str(spec_file), "--scheduler", "serial", "--no-progress",
                 "--evidence", str(folder)]) == 1
    assert f"evidence not written to {folder}: rerun to retry the failed runs" in \
        capsys.readouterr().out
    assert not folder.exists()


@pytest.mark.parametrize(("args", "message"), [
    (["--frames", "0"], "sweep: frames=0 out of range (frames >= 1)"),
    (["--scheduler", "mars"], "--scheduler: sweep: scheduler='mars': expected serial"),
    (["--workers", "0"], "--workers: sweep: workers=0 out of range (workers >= 1)"),
    (["--seeds", "-1"], "sweep: seeds=[-1] out of range (a non-empty list of integers >= 0)"),
])
def test_bad_options_are_one_line_errors(spec_file, capsys, args, message):
    assert main(["sweep", str(spec_file), "--no-progress", *args]) == 2
    err = capsys.readouterr().err
    assert err.startswith("alte sweep: error: ") and message in err and err.count("\n") == 1


def test_bad_spec_is_a_one_line_error(tmp_path, capsys):
    path = tmp_path / "bad.yaml"
    path.write_text("terrains: [sim_lan_1]\nmappers: {alte2d: {grid: {kappa: [-1]}}}\n")
    assert main(["sweep", str(path)]) == 2
    assert "bad.yaml: mappers.alte2d: alte2d: kappa=-1.0 out of range" in capsys.readouterr().err
    assert main(["sweep", str(tmp_path / "none.yaml")]) == 2
    assert "none.yaml: cannot read it" in capsys.readouterr().err
