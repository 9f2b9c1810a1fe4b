"""A sweep on a real Dask cluster: ``dask scheduler`` and ``dask worker`` processes on
loopback, started as a user would start them on other machines
(docs/how-to/dask-cluster.md), give the rows of a serial run; the processes are stopped
whatever happens."""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from alte.lab.studies.sweep import TIMING_COLUMNS, parse_spec, run_sweep

STARTUP_S = 90.0


def _dask() -> str:
    found = shutil.which("dask", path=str(Path(sys.executable).parent)) or shutil.which("dask")
    if found is None:
        pytest.skip("the dask command line is not installed")
    return found


def _start(args: list[str], log: Path) -> subprocess.Popen[bytes]:
    env = {**os.environ, "NUMBA_NUM_THREADS": "1"}  # the workers are the parallelism
    with log.open("wb") as out:
        return subprocess.Popen(args, stdout=out, stderr=subprocess.STDOUT, env=env,
                                start_new_session=True)


def _stop(proc: subprocess.Popen[bytes]) -> None:
    if proc.poll() is not None:
        return
    os.killpg(proc.pid, signal.SIGTERM)  # the worker's nanny and its worker process
    try:
        proc.wait(timeout=20)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()


def _address(file: Path, scheduler: subprocess.Popen[bytes], log: Path) -> str:
    deadline = time.monotonic() + STARTUP_S
    while time.monotonic() < deadline:
        if scheduler.poll() is not None:
            pytest.skip(f"dask scheduler exited at start: {log.read_text()[-500:]}")
        if file.is_file():
            try:
                return str(json.loads(file.read_text())["address"])
            except (ValueError, KeyError):
                pass  # being written
        time.sleep(0.2)
    pytest.skip(f"dask scheduler did not start within {STARTUP_S:.0f} s")


@pytest.fixture
def cluster(tmp_path: Path) -> Iterator[str]:
    """The address of a scheduler with one worker process (one thread), on 127.0.0.1."""
    dask = _dask()
    file = tmp_path / "scheduler.json"
    procs = [_start([dask, "scheduler", "--host", "127.0.0.1", "--port", "0",
                     "--no-dashboard", "--scheduler-file", str(file)],
                    tmp_path / "scheduler.log")]
    try:
        address = _address(file, procs[0], tmp_path / "scheduler.log")
        procs.append(_start([dask, "worker", address, "--nthreads", "1", "--nworkers", "1",
                             "--no-dashboard", "--local-directory", str(tmp_path / "work")],
                            tmp_path / "worker.log"))
        from distributed import Client

        with Client(address, timeout="30s") as client:
            try:
                client.wait_for_workers(1, timeout=STARTUP_S)
            except TimeoutError:
                pytest.skip("dask worker did not join: "
                            f"{(tmp_path / 'worker.log').read_text()[-500:]}")
        yield address
    finally:
        for proc in reversed(procs):
            _stop(proc)


@pytest.mark.slow
def test_sweep_on_a_scheduler_and_worker_processes(cluster: str, tmp_path: Path) -> None:
    raw = {"terrains": ["sim_lan_1"], "frames": 2, "truth": {"n_samples": 500},
           "data_dir": str(tmp_path / "data"),
           "mappers": {"alte2d": {"grid": {"kappa": [0.1, 1.0], "max_res": [4]}},
                       "quadtree": {"rows": [{"max_points": 300}]}}}
    spec = parse_spec(raw, "cluster")
    remote = run_sweep(spec, scheduler=cluster, output=tmp_path / "remote", progress=False)
    assert (remote.ran, remote.failed) == (3, [])
    serial = run_sweep(spec, scheduler="serial", output=tmp_path / "serial", progress=False)
    keep = [c for c in serial.table.columns if c not in TIMING_COLUMNS]
    assert remote.table[keep].equals(serial.table[keep])
    again = run_sweep(spec, scheduler=cluster, output=tmp_path / "remote", progress=False)
    assert (again.ran, again.skipped) == (0, 3)  # resumed: nothing left to run


def test_a_closing_local_cluster_keeps_its_nannies_quiet_and_only_then(monkeypatch) -> None:
    """While the work runs a nanny's warnings show (a worker restarted); while the cluster
    closes they do not (a worker killed 4 s after the close is no news); after it the
    logger is as it was. The scheduler restarts a silent worker after WORKER_TTL."""
    import logging

    import dask
    import distributed

    from alte.lab.studies.sweep import runner

    nanny = logging.getLogger("distributed.nanny")
    levels: dict[str, int] = {}
    ttl: dict[str, str] = {}

    class Cluster:
        def __init__(self, **kwargs: object) -> None:
            levels["workers"] = int(str(kwargs["n_workers"]))
            ttl["set"] = dask.config.get("distributed.scheduler.worker-ttl")

        def __enter__(self) -> Cluster:
            return self

        def __exit__(self, *exc: object) -> None:
            levels["closing"] = nanny.getEffectiveLevel()

    class Client:
        def __init__(self, cluster: Cluster) -> None:
            pass

        def __enter__(self) -> Client:
            return self

        def __exit__(self, *exc: object) -> None:
            pass

    monkeypatch.setattr(distributed, "LocalCluster", Cluster)
    monkeypatch.setattr(distributed, "Client", Client)
    monkeypatch.setattr(runner, "_dask_map", lambda client: client)
    nanny.setLevel(logging.NOTSET)
    with runner.executor("local", 2):
        levels["working"] = nanny.getEffectiveLevel()
    assert levels["workers"] == 2 and levels["working"] <= logging.WARNING
    assert levels["closing"] == logging.ERROR and nanny.level == logging.NOTSET
    assert ttl["set"] == runner.WORKER_TTL == "90s"  # a hung worker restarted, not waited for
    with pytest.raises(RuntimeError, match="task"), runner.executor("local", 1):
        raise RuntimeError("task failed")
    assert levels["closing"] == logging.ERROR and nanny.level == logging.NOTSET


def test_a_local_cluster_leaves_port_8787_alone() -> None:
    """Two clusters at once (two sweeps, two test workers) do not fight over distributed's
    default HTTP port: with 8787 taken, a cluster of the sweep's options starts without
    the 'Port 8787 is already in use' warning."""
    import socket
    import warnings

    from distributed import LocalCluster

    from alte.lab.studies.sweep.runner import CLUSTER_OPTIONS

    holder = socket.socket()
    try:
        holder.bind(("", 8787))
        holder.listen()
    except OSError:
        pass  # taken already: the case itself
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            with LocalCluster(n_workers=0, **{**CLUSTER_OPTIONS, "processes": False}) as cluster:
                assert cluster.scheduler.http_server.port != 8787
    finally:
        holder.close()
