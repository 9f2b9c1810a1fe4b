"""Tests for the chapter 4-5 experiments: terrains registered once, maps measured, sweeps,
and the command line reproducing a table row."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from alte.cli import main
from alte.errors import ParameterError
from alte.lab.studies import experiments
from alte.lab.studies.experiments import CACHE_DIR, ground_truth, measure, sweep, terrain, timed_run
from alte.mappers.domain import Domain
from alte.metrics.maps import TruthSettings
from alte.pipeline import MapSettings

FRAMES = 4
TRUTH = TruthSettings(n_samples=5000, grid_step=0.5)


@pytest.fixture(scope="module")
def data_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return tmp_path_factory.mktemp("data")


@pytest.fixture(scope="module")
def lan(data_dir: Path):
    return terrain("sim_lan_2", data_dir, frames=FRAMES)


@pytest.fixture(scope="module")
def nav(data_dir: Path):
    return terrain("sim_nav_1", data_dir, frames=FRAMES)


def test_terrain_is_simulated_registered_and_cached(data_dir: Path, lan) -> None:
    assert lan.source.name == "sim_lan_2" and len(lan) == FRAMES
    assert lan.source.path == data_dir / f"sim_lan_2-{FRAMES}f"
    assert (data_dir / CACHE_DIR / lan.key / "meta.json").is_file()
    truth = ground_truth(lan)
    assert truth is not None and np.all(truth.surface.distance(lan.cloud) < 1.0)
    again = terrain("sim_lan_2", data_dir, frames=FRAMES)
    assert again.key == lan.key and isinstance(again.points, np.memmap)
    with pytest.raises(ParameterError, match="frames=0"):
        terrain("sim_lan_2", data_dir, frames=0)


@pytest.mark.parametrize(("mapper", "params"), [("quadtree", {"max_points": 50}),
                                                ("alte2d", {"max_res": 5})])
def test_measure_times_and_measures_2d_maps(lan, mapper: str, params: dict) -> None:
    run = measure(lan, mapper, params, truth=TRUTH)
    m = run.metrics
    assert m.elapsed_s > 0 and m.basis_functions == run.mapper.basis_functions
    assert m.hd_m >= m.mhd_m >= 0
    assert m.hd_minus_mhd_m == pytest.approx(m.hd_m - m.mhd_m)
    assert m.truth is not None and 0 <= m.truth.unknown_share <= 1
    assert m.truth.completeness > 0.3 and m.truth.height_rmse_m < 1.0


def test_a_cheap_map_is_timed_as_the_least_of_repeated_runs(lan, monkeypatch) -> None:
    result, timing = timed_run(lan, MapSettings("alte2d", {"max_res": 5}))
    assert timing.repeats == experiments.REPEATS == 3
    assert timing.cpu_s > 0 and timing.elapsed_s > 0 and timing.cpu_spread >= 0
    m = measure(lan, "alte2d", {"max_res": 5}).metrics
    assert (m.time_repeats, m.cost) == (3, result.mapper.cost) and m.map_cpu_s > 0
    # a map dearer than the threshold is timed once: no spread measured
    monkeypatch.setattr(experiments, "REPEAT_BELOW_S", 0.0)
    once = timed_run(lan, MapSettings("alte2d", {"max_res": 5}))[1]
    assert once.repeats == 1 and np.isnan(once.cpu_spread)
    with pytest.raises(ParameterError, match="repeats=0: expected at least 1"):
        timed_run(lan, MapSettings("alte2d"), repeats=0)


def test_measure_without_truth_has_only_thesis_metrics(lan) -> None:
    m = measure(lan, "quadtree", {"max_points": 200}).metrics
    assert m.truth is None and "completeness" not in m.flat() and "mhd_m" in m.flat()


def test_alte3d_gets_the_control_volume_cube(nav) -> None:
    run = measure(nav, "alte3d", {"max_res": 4, "min_pts": 2, "min_pts_split": 5,
                                  "occupancy_level": 4}, truth=TRUTH)
    assert nav.spec.crop is not None
    assert run.run.info.domain == Domain.over(nav.spec.crop)
    assert run.run.info.domain_policy == "control"
    assert run.metrics.basis_functions > 0 and run.metrics.truth is not None


def test_empty_map_gets_nan_hausdorff(nav) -> None:
    m = measure(nav, "alte3d", {"max_res": 2, "min_pts": 10_000, "min_pts_split": 5}).metrics
    assert m.occupied_cells == 0 and math.isnan(m.mhd_m)


def test_sweep_puts_our_metrics_beside_the_thesis_columns(lan) -> None:
    table, runs = sweep(lan, 7, rows=[0, 5], progress=False)
    assert table["max_points"].tolist() == [25, 1000]
    assert table["thesis_row"].tolist() == [0, 5]
    assert table["thesis_elapsed_s"].tolist() == [43.38, 0.62]
    assert len(runs) == 2
    assert runs[0].metrics.basis_functions > runs[1].metrics.basis_functions


@pytest.mark.parametrize(("mapper", "params", "data"),
                         [("quadtree", {"max_points": 50}, "lan"),
                          ("octomap", {"resolution": 2.0}, "nav")])
def test_a_prepared_reference_measures_what_each_map_alone_does(
        request: pytest.FixtureRequest, mapper: str, params: dict, data: str) -> None:
    """A sweep prepares its cloud and truth once (``reference_of``): every figure but the
    time equals that of a map measured on its own."""
    registered = request.getfixturevalue(data)
    reference = experiments.reference_of(registered, TRUTH)
    alone = measure(registered, mapper, params, truth=TRUTH).metrics.flat()
    for _ in range(2):  # the second map reads what the first prepared
        shared = measure(registered, mapper, params, truth=TRUTH,
                         reference=reference).metrics.flat()
        timing = {k for k in alone if k.startswith(("elapsed", "map_cpu"))}
        assert {k: v for k, v in shared.items() if k not in timing} == pytest.approx(
            {k: v for k, v in alone.items() if k not in timing}, rel=0, abs=0, nan_ok=True)


@pytest.mark.parametrize(("table", "rows", "match"), [(5, None, "not a sweep"),
                                                     (7, [6], r"rows \[6\] not in 0..5"),
                                                     (7, [], r"rows \[\] not in 0..5")])
def test_sweep_rejects_bad_tables_and_rows(lan, table: int, rows, match: str) -> None:
    with pytest.raises(ParameterError, match=match):
        sweep(lan, table, rows=rows, progress=False)


ROWS = [("sim_lan_2", "quadtree", {"max_points": 100}),
        ("sim_lan_2", "alte2d", {"kappa": 0.01, "max_res": 5, "min_pts": 10}),
        ("sim_nav_1", "alte3d", {"max_res": 6, "min_pts": 10, "min_pts_split": 20}),
        ("sim_nav_1", "octomap", {"resolution": 0.2})]


@pytest.mark.parametrize(("name", "mapper", "params"), ROWS)
def test_cli_on_the_terrain_folder_reproduces_the_table_row(
        capsys: pytest.CaptureFixture[str], request: pytest.FixtureRequest, name: str,
        mapper: str, params: dict) -> None:
    data = request.getfixturevalue("lan" if name == "sim_lan_2" else "nav")
    row = measure(data, mapper, params, truth=TruthSettings())
    sets = [a for k, v in params.items() for a in ("--set", f"{k}={v}")]
    assert main(["map", str(data.source.path), "--mapper", mapper, *sets, "--metrics",
                 "--json"]) == 0
    cli = json.loads(capsys.readouterr().out)
    timing = {"elapsed_s", "elapsed_spread", "map_cpu_s", "map_cpu_spread", "time_repeats"}
    ours = {k: v for k, v in row.metrics.as_dict().items() if k not in timing}
    theirs = {k: v for k, v in cli["metrics"].items() if k not in timing}
    assert cli["metrics"]["time_repeats"] == 1 and cli["metrics"]["map_cpu_s"] > 0
    assert json.loads(json.dumps(ours)) == theirs
    assert cli["basis_functions"] == row.metrics.basis_functions
    assert cli["domain"] == (None if row.run.info.domain is None
                             else row.run.info.domain.as_dict())
