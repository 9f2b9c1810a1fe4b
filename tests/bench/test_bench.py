"""The benchmark code itself, on tiny inputs (nothing here asserts a speed)."""

import json
import math
import os
import threading

import numpy as np
import pytest

from alte.cli import main
from alte.errors import ParameterError
from alte.lab.report.runs import point_latest, write_record
from alte.mappers import registry
from alte.paths import realdata_dir
from bench.core import BenchSettings, Context, Result
from bench.output import format_value, miss_note, render_markdown, write_outputs
from bench.runner import ROWS, run_bench, select_rows
from bench.scaling import predicted_seconds, whole_scans
from bench.timing import (
    fit_exponent,
    interleave,
    machine_info,
    measure,
    nlogn_exponent,
    one_core,
)
from bench.wall import report_wall_time, stage_shares, thesis_total_s
from bench.workload import tile_points

REALDATA = realdata_dir()


def test_measure_interleaves_alternating_and_drops_the_warmup():
    log = []
    samples = measure({"a": lambda: log.append("a"), "b": lambda: log.append("b")},
                      repeats=3, warmup=1)
    assert log == ["a", "b", "b", "a", "a", "b", "b", "a"]
    assert [len(s.times) for s in samples.values()] == [3, 3]
    assert samples["a"].median >= 0 and samples["a"].as_dict()["repeats"] == 3
    assert list(interleave(["x", "y"], 2)) == [(0, "x"), (0, "y"), (1, "y"), (1, "x")]


@pytest.mark.skipif(not hasattr(os, "sched_setaffinity"), reason="CPU affinity is Linux only")
def test_one_core_pins_every_thread_and_restores_the_masks():
    before = os.sched_getaffinity(0)
    waiting, seen = threading.Event(), {}

    def later() -> None:  # a thread that exists before the block, asks inside it
        waiting.wait()
        seen["older"] = os.sched_getaffinity(0)

    older = threading.Thread(target=later)
    older.start()
    with one_core() as cpu:
        assert cpu == min(before) and os.sched_getaffinity(0) == {cpu}
        waiting.set()
        older.join()
        newer = threading.Thread(target=lambda: seen.update(newer=os.sched_getaffinity(0)))
        newer.start()
        newer.join()
    assert seen == {"older": {cpu}, "newer": {cpu}}  # started before or inside the block
    assert os.sched_getaffinity(0) == before


@pytest.mark.parametrize(("repeats", "warmup", "match"),
                         [(0, 1, "repeats=0"), (3, -1, "warmup=-1")])
def test_measure_rejects_bad_counts(repeats, warmup, match):
    with pytest.raises(ParameterError, match=match):
        measure({"a": lambda: None}, repeats=repeats, warmup=warmup)


def test_fit_exponent_recovers_power_laws_and_nlogn_bar():
    n = np.array([1e4, 1e5, 1e6, 1e7])
    assert fit_exponent(n, 3e-9 * n**2) == pytest.approx(2.0)
    assert fit_exponent(n, 5e-7 * n) == pytest.approx(1.0)
    assert 1.05 < nlogn_exponent(n) < 1.15
    with pytest.raises(ParameterError, match="need >= 2"):
        fit_exponent([10], [1.0])
    with pytest.raises(ParameterError, match="need >= 2"):
        fit_exponent([10, 10], [1.0, 2.0])


def test_predicted_seconds_extrapolates_at_least_linearly():
    assert predicted_seconds([10], [1.0], 100) == pytest.approx(10.0)
    assert predicted_seconds([10, 100], [1.0, 100.0], 1000) == pytest.approx(10000.0)
    assert predicted_seconds([10, 100], [1.0, 1.0], 1000) == pytest.approx(10.0)


def test_tile_points_subsamples_and_tiles_without_overlap():
    rng = np.random.default_rng(1)
    pts = rng.random((100, 3)) * [10, 5, 1]
    origins = np.repeat(np.arange(10.0), 10)[:, None] * [1, 0, 0]
    (small,) = tile_points(pts, 30)
    assert small.shape == (30, 3) and np.isin(small[:, 0], pts[:, 0]).all()
    big, big_origins = tile_points(pts, 450, origins)
    assert big.shape == (450, 3) and big_origins.shape == (450, 3)
    shift = big - big_origins  # points keep their offset from their own origin
    assert np.isin(np.round(shift, 9), np.round(pts - origins, 9)).all()
    assert np.unique(np.round(big, 9), axis=0).shape[0] == 450
    with pytest.raises(ParameterError, match="count >= 1"):
        tile_points(pts, 0)


def test_whole_scans_keeps_scans_whole_and_tiles_the_mission():
    frames = [(np.full((10, 3), float(i)), np.array([float(i), 0.0, 5.0])) for i in range(8)]
    pts, origins = whole_scans(frames, 40)
    assert len(pts) == 40 and len(np.unique(origins[:, 0])) == 4  # 4 of the 8 scans, whole
    assert (pts[:, 0] == origins[:, 0]).all()
    pts, origins = whole_scans(frames, 150)
    assert len(pts) == 160 and len(np.unique(origins, axis=0)) == 16  # two copies of 8 scans


def test_config_and_row_selection_errors():
    with pytest.raises(ParameterError, match="frames=0"):
        BenchSettings(frames=0)
    with pytest.raises(ParameterError, match="sizes"):
        BenchSettings(sizes=(1, 10))
    with pytest.raises(ParameterError, match="budget_s"):
        BenchSettings(budget_s=0)
    with pytest.raises(ParameterError, match=r"unknown row\(s\) \[99\]"):
        select_rows([1, 99])
    assert select_rows(None) == sorted(ROWS) == list(range(1, 17))
    assert BenchSettings(quick=True).scaling_sizes == (3000, 6000, 12000)
    assert BenchSettings().scaling_sizes[-1] == 10**7


def test_thesis_total_and_stage_shares():
    assert thesis_total_s() == pytest.approx(321.86, abs=0.01)
    shares = stage_shares({"seconds": 10.0, "runs": [{"name": "a", "seconds": 6.0},
                                                     {"name": "b", "seconds": 3.0}]})
    assert shares["a"] == pytest.approx(0.6)
    assert sum(shares.values()) == pytest.approx(1.0)
    assert stage_shares({"seconds": 0}) == {}


def test_row8_reads_the_latest_report_record_or_says_not_run(tmp_path):
    ctx = Context(BenchSettings(reports_dir=tmp_path))
    (missing,) = report_wall_time(ctx)
    assert missing.detail["status"] == "not run" and math.isnan(missing.ours)
    run_dir = tmp_path / "runs" / "20240101T000000Z"
    run_dir.mkdir(parents=True)
    write_record(run_dir, {"mode": "quick", "started": "2024-01-01", "seconds": 20.0,
                           "runs": [{"name": "ch5", "status": "ok", "seconds": 15.0}]})
    point_latest(tmp_path, run_dir)
    (row,) = report_wall_time(ctx)
    assert row.ours == 20.0 and row.peer == pytest.approx(thesis_total_s())
    assert row.detail["shares"]["ch5"] == pytest.approx(0.75)


@pytest.mark.parametrize(("mode", "cpu_s", "met"), [("full", 1100.0, True),
                                                    ("full", 1300.0, False),
                                                    ("quick", 1300.0, None)])
def test_row8_holds_a_full_report_to_its_budget_in_cpu_seconds(tmp_path, mode, cpu_s, met):
    """A record with the report's CPU seconds adds the budget line: CPU s over the two
    cores against 600 s, judged for a full report only."""
    run_dir = tmp_path / "runs" / "20240101T000000Z"
    run_dir.mkdir(parents=True)
    write_record(run_dir, {"mode": mode, "started": "2024-01-01", "seconds": 2000.0,
                           "cpu_s": cpu_s, "load_average": {"start": 9.0, "end": 12.0},
                           "runs": []})
    point_latest(tmp_path, run_dir)
    wall, budget = report_wall_time(Context(BenchSettings(reports_dir=tmp_path)))
    assert wall.ours == 2000.0
    assert (budget.ours, budget.peer, budget.met) == (cpu_s / 2, 600.0, met)
    assert budget.detail["load_average"] == {"start": 9.0, "end": 12.0}


def test_a_failing_row_is_recorded_and_the_others_still_run(monkeypatch, tmp_path):
    def broken(ctx):
        raise ValueError("boom")

    monkeypatch.setitem(ROWS, 99, ("broken", broken))
    bench = run_bench(BenchSettings(reports_dir=tmp_path, progress=False), [8, 99])
    assert "ValueError: boom" in bench.errors[99]
    assert [r.row for r in bench.results] == [8]
    assert "Rows that failed" in render_markdown(bench)


def test_formatting_and_miss_notes():
    assert format_value(3 * 2**20, "B") == "3.0 MiB"
    assert format_value(2e-5, "s") == "20 us"
    assert format_value(float("nan"), "s") == "n/a"
    slow = Result(3, "quadtree build", 30.0, 2.0, "s", "ratio <= 10", False)
    assert "missed by 1.50x" in miss_note(slow)
    assert miss_note(Result(3, "ok", 1.0, 1.0, "s", "ratio <= 10", True)) == ""
    late = Result(12, "odometry per scan", 156.0, 91.4, "ms", "< 100 ms", False)
    assert miss_note(late) == "row 12 odometry per scan: 156 ms, target < 100 ms"
    assert machine_info()["cores"] >= 1


@pytest.fixture(scope="module")
def quick_bench(tmp_path_factory):
    """Every row on a few simulated scans, one repeat, no warm-up."""
    root = tmp_path_factory.mktemp("bench")
    config = BenchSettings(quick=True, repeats=1, warmup=0, frames=3, sizes=(3000, 12000),
                         data_dir=root / "data", reports_dir=root / "reports", progress=False)
    return run_bench(config)


@pytest.mark.full
@pytest.mark.slow
def test_quick_bench_runs_every_row_and_writes_its_outputs(quick_bench):
    assert quick_bench.errors == {}
    rows = set(range(1, 12)) | {13, 16}
    rows |= {12} if (REALDATA / "balm_seq").exists() else set()
    rows |= {14} if (REALDATA / "als").exists() else set()
    rows |= {15} if (REALDATA / "isprs_terrain").exists() else set()
    assert {r.row for r in quick_bench.results} == rows
    for r in quick_bench.results:
        if r.row != 8:
            assert math.isfinite(r.ours) and r.peer > 0, r.case
    row1 = next(r for r in quick_bench.results if r.row == 1)
    assert row1.detail["jaccard"] == 1.0 and row1.detail["frames"] == 3
    assert row1.detail["leaves_native"] == row1.detail["leaves_reference"] > 0
    hd = [r for r in quick_bench.results if r.row == 4]
    assert all(r.detail["hd_m"] == r.detail["hd_open3d_m"] for r in hd)
    assert all(r.detail["mhd_m"] == r.detail["mhd_open3d_m"] for r in hd)
    mappers = registry.classes()  # the thesis' four and the installed plugins
    latency = [r for r in quick_bench.results if r.row == 5]
    assert len(latency) == sum(cls.incremental for cls in mappers)
    assert [r.detail["same"] for r in latency if "same" in r.detail] == [True, True]
    chain = [r for r in quick_bench.results if r.row == 10]
    assert len(chain) == 2 * len(mappers) and all(r.detail["frames"] == 6 for r in chain)
    assert all(r.detail["latency_ms"]["max"] >= r.detail["insert_ms"]["max"] for r in chain)
    assert [r.detail["frames"] for r in quick_bench.results if r.row == 11] == [3]
    poses = [r for r in quick_bench.results if r.row == 12]
    assert len(poses) in (0, 4) and all(r.detail["scans"] == 20 and r.peer > 0 for r in poses)
    lio = [r for r in quick_bench.results if r.row == 16]
    assert [r.case.split(",")[1] for r in lio] == [" mean", " median"]
    assert all(r.detail["scans"] == 60 and r.ours > 0 and r.peer > 0 for r in lio)
    sweeps = [r for r in quick_bench.results if r.row == 13]
    assert [r.case.split(" (")[0] for r in sweeps] == [
        "sweep runs per core-second, 20 scans", "sweep runs per core-second, whole missions"]
    for r in sweeps:  # grouped runs beat today's run-by-run path; the grid is estimated
        assert r.ours > r.peer and r.detail["grid_cpu_h"] > 0 and r.met is None
        assert r.detail["grid_runs"] > r.detail["sample_runs"] >= 12
        assert len(r.detail["per_stratum"]) == 12
    paths = write_outputs(quick_bench, quick_bench.config.reports_dir)
    record = json.loads(paths["json"].read_text())
    assert record["machine"]["cpu"] and len(record["results"]) == len(quick_bench.results)
    text = paths["md"].read_text()
    assert "| # | case | ours | peer | ratio ours/peer | target | met |" in text
    assert paths["png"].stat().st_size > 0


def test_cli_bench_quick_only_cheap_rows(tmp_path, capsys):
    code = main(["bench", "--quick", "--only", "8", "--repeats", "1", "--warmup", "0",
                 "--reports", str(tmp_path), "--no-progress"])
    assert code == 0
    assert "make report (not run" in capsys.readouterr().out
    assert (tmp_path / "bench.md").is_file() and (tmp_path / "bench.json").is_file()
    with pytest.raises(SystemExit):
        main(["bench", "--only", "x"])
