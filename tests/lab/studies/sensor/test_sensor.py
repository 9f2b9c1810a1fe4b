"""The realistic UAV sensor against the thesis' instantaneous scan
(alte.lab.studies.sensor.experiment)."""

from __future__ import annotations

import math

import pytest

from alte.errors import ParameterError
from alte.lab.studies.sensor.experiment import RUN_TEXT, RUNS, sensor_row, sensor_table, sensor_view


def test_deskewing_the_uav_sweep_brings_the_cloud_back_to_the_thesis_scan(tmp_path):
    """Six scans of SIM NAV 1 (5 m/s): the sweep smears the cloud taken as it is; with
    recorded poses and deskew it lands within 2 cm of the instantaneous scan's."""
    row = sensor_row("sim_nav_1", tmp_path, runs=("thesis", "recorded", "deskew"), frames=6)
    assert row["terrain"] == "sim_nav_1" and 270 < float(row["path_m"]) < 290
    assert float(row["mesh_thesis_m"]) < 0.02
    assert float(row["mesh_recorded_m"]) > 4 * float(row["mesh_deskew_m"])
    assert abs(float(row["mesh_deskew_m"]) - float(row["mesh_thesis_m"])) < 0.02
    for key in ("thesis", "recorded", "deskew"):
        assert float(row[f"ate_{key}_m"]) < 1e-3  # recorded poses are the truth here
        assert float(row[f"cpu_ms_per_scan_{key}"]) > 0
    assert "ate_lio_m" not in row and set(RUNS) >= {"lidar", "lio"}


def test_the_table_has_a_row_per_terrain(tmp_path):
    table = sensor_table(["sim_lan_2"], tmp_path, runs=("recorded",), frames=3)
    assert list(table["terrain"]) == ["sim_lan_2"]
    assert not math.isnan(table["mesh_recorded_m"].iloc[0])
    assert list(table["seed"]) == [0]
    made = table.assign(ate_recorded_m=0.50004, path_m=200.0, rpe_recorded_pct=1.5,
                        mesh_recorded_m=0.04, cpu_ms_per_scan_recorded=30.04)
    assert sensor_view(made).to_dict("records") == [{
        "terrain": "sim_lan_2", "run": RUN_TEXT["recorded"], "seeds": 1, "ATE (m)": 0.5,
        "ATE (% of path)": 0.25, "ATE, worst seed (% of path)": 0.25, "RPE (% per m)": 1.5,
        "cloud to true mesh, mean (m)": 0.04, "cloud to true mesh, worst seed (m)": 0.04,
        "CPU per scan (ms)": 30.0}]  # rounded to mm and 0.1 ms


@pytest.mark.full
def test_two_worker_processes_give_the_serial_rows_in_the_order_asked(tmp_path):
    """A local Dask cluster of two processes (chapter 5's scheduler) gives the serial rows,
    in the order asked (each seed its own task)."""
    table = sensor_table(["sim_lan_2"], tmp_path, seeds=[1, 0], runs=("recorded",), frames=3,
                         scheduler="local", workers=2)
    assert list(zip(table["terrain"], table["seed"], strict=True)) == [("sim_lan_2", 1),
                                                                         ("sim_lan_2", 0)]
    serial = sensor_table(["sim_lan_2"], tmp_path, seeds=[1, 0], runs=("recorded",), frames=3)
    assert list(table["mesh_recorded_m"]) == list(serial["mesh_recorded_m"])


def test_seeds_give_a_row_each_and_the_view_their_mean_and_worst(tmp_path, monkeypatch):
    """Each seed is its own task and its row lands in the order asked, whatever order the
    tasks end in (here: the last first, as a worker pool may finish them; the pool itself:
    the sweep's Dask tests, and the two-process run above in ``make check-full``)."""
    from contextlib import contextmanager

    from alte.lab.studies.sweep import runner

    tasks, serial_executor = [], runner.executor

    @contextmanager
    def last_first(scheduler, workers):
        if scheduler == "serial":
            with serial_executor(scheduler, workers) as pool:
                yield pool
            return
        assert (scheduler, workers) == ("local", 2)

        def pool(fn, items, data_dir):
            tasks.extend(items)
            yield from reversed(list(runner._serial_map(fn, items, data_dir)))
        yield pool

    monkeypatch.setattr(runner, "executor", last_first)
    table = sensor_table(["sim_lan_2"], tmp_path, seeds=[1, 0], runs=("recorded",), frames=3,
                         scheduler="local", workers=2)
    assert [(name, seed) for name, seed, *_ in tasks] == [("sim_lan_2", 1), ("sim_lan_2", 0)]
    assert list(zip(table["terrain"], table["seed"], strict=True)) == [("sim_lan_2", 1),
                                                                         ("sim_lan_2", 0)]
    serial = sensor_table(["sim_lan_2"], tmp_path, seeds=[1, 0], runs=("recorded",), frames=3)
    assert list(table["mesh_recorded_m"]) == list(serial["mesh_recorded_m"])
    assert table["mesh_recorded_m"].nunique() == 2
    made = table.assign(ate_recorded_m=[1.0, 3.0], path_m=200.0, rpe_recorded_pct=[1.0, 2.0],
                        mesh_recorded_m=[0.04, 0.08], cpu_ms_per_scan_recorded=[30.0, 50.0])
    row = sensor_view(made).iloc[0]
    assert (row["seeds"], row["ATE (m)"], row["ATE (% of path)"]) == (2, 2.0, 1.0)
    assert row["ATE, worst seed (% of path)"] == 1.5 and row["RPE (% per m)"] == 1.5
    assert row["cloud to true mesh, mean (m)"] == 0.06
    assert row["cloud to true mesh, worst seed (m)"] == 0.08
    assert row["CPU per scan (ms)"] == 40.0


def test_an_empty_seed_list_is_refused(tmp_path):
    with pytest.raises(ParameterError, match="sensor study: seeds is empty"):
        sensor_table(["sim_lan_2"], tmp_path, seeds=[])


def test_an_unknown_run_is_named_with_the_valid_ones(tmp_path):
    with pytest.raises(ParameterError, match="sensor runs imu: valid: thesis, recorded, "
                                             "deskew, lidar, lio"):
        sensor_row("sim_nav_1", tmp_path, runs=("imu",))
    with pytest.raises(ParameterError, match="sensor runs imu: valid: thesis"):
        sensor_table(["sim_nav_1"], tmp_path, runs=("imu",))
