"""Run order for ``make test`` (``pytest -n 2 --dist loadfile --no-loadscope-reorder``).

xdist hands whole files to the two workers, one at a time as each runs dry, in the
collection order (``--no-loadscope-reorder``: its default orders files by their number
of tests, which says little about time). A long file handed out last leaves one core
idle while the other finishes it, so files holding a ``slow`` test and the notebooks go
first; the many short files then fill both workers to the end. Within a file the order
stays.
"""

from __future__ import annotations

import resource
from collections.abc import Generator

import pytest

#: Notebooks whose headless run (nbval) is a long end-to-end check: ``make check-full``
#: (tests/README.md: which smaller tests prove their parts in ``make test``). ``make test``
#: executes ``ch4_terrain`` and reads every notebook's calls (tests/notebooks/test_calls.py).
FULL_NOTEBOOKS: frozenset[str] = frozenset({
    "ch2_test_benchmark.ipynb", "ch3_mapping_techniques.ipynb", "ch5_analysis.ipynb",
    "ch6_real_data.ipynb", "ch7_landing.ipynb", "ch7_planning.ipynb",
    "ch7_sensitivity.ipynb"})


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """Long files first (stable: files and their tests keep their relative order); the
    long notebooks' cells marked ``full``."""
    for item in items:
        if item.path.name in FULL_NOTEBOOKS:
            item.add_marker(pytest.mark.full)
    long_files = {item.path for item in items
                  if item.get_closest_marker("slow") or item.path.suffix == ".ipynb"}
    items.sort(key=lambda item: item.path not in long_files)


def pytest_addoption(parser: pytest.Parser) -> None:
    """``--update-reference``: rewrite tests/reference's expected tables from this run
    (``make reference``; a deliberate change whose diff a reviewer reads)."""
    parser.addoption("--update-reference", action="store_true", default=False,
                     help="rewrite the expected tables of tests/reference from this run")
    parser.addoption("--cpu-durations", type=int, default=None, metavar="N",
                     help="show the N tests that took the most CPU seconds (the test's "
                          "process and the children it waited for: CLI runs, kernels)")


def _cpu_s() -> float:
    own, children = (resource.getrusage(who) for who in
                     (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN))
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


def _timed(item: pytest.Item) -> Generator[None]:
    start = _cpu_s()
    yield
    item.stash[_CPU] = item.stash.get(_CPU, 0.0) + _cpu_s() - start


_CPU = pytest.StashKey[float]()
_CPU_SEEN: dict[str, float] = {}


@pytest.hookimpl(wrapper=True)
def pytest_runtest_setup(item: pytest.Item) -> Generator[None]:
    """CPU seconds per test (setup, call and teardown): on a shared machine the wall
    time measures the others' load; ``--cpu-durations`` and the JUnit XML report it."""
    return (yield from _timed(item))


@pytest.hookimpl(wrapper=True)
def pytest_runtest_call(item: pytest.Item) -> Generator[None]:
    return (yield from _timed(item))


@pytest.hookimpl(wrapper=True)
def pytest_runtest_teardown(item: pytest.Item) -> Generator[None]:
    result = yield from _timed(item)
    item.user_properties.append(("cpu_s", round(item.stash.get(_CPU, 0.0), 3)))
    return result


def pytest_runtest_logreport(report: pytest.TestReport) -> None:
    """Collect each test's CPU seconds (from the xdist workers too)."""
    if report.when == "teardown":
        for name, value in report.user_properties:
            if name == "cpu_s" and isinstance(value, float):
                _CPU_SEEN[report.nodeid] = value


def pytest_terminal_summary(terminalreporter: pytest.TerminalReporter,
                            config: pytest.Config) -> None:
    """``--cpu-durations N``: the N tests with the most CPU seconds, and the total."""
    count = config.getoption("--cpu-durations")
    if count is None or not _CPU_SEEN:
        return
    ranked = sorted(_CPU_SEEN.items(), key=lambda kv: -kv[1])
    terminalreporter.write_sep("=", f"most CPU seconds ({sum(_CPU_SEEN.values()):.0f} "
                                    f"CPU s over {len(_CPU_SEEN)} tests)")
    for nodeid, seconds in ranked[:count]:
        terminalreporter.write_line(f"{seconds:8.2f}s  {nodeid}")


#: Scans of a terrain :func:`small_terrain` simulates unless told otherwise.
SMALL = 40


@pytest.fixture(scope="session")
def small_data(tmp_path_factory: pytest.TempPathFactory):
    """Folder holding the terrains :func:`small_terrain` simulates (one per test process)."""
    return tmp_path_factory.mktemp("simdata")


@pytest.fixture(scope="session")
def small_terrain(small_data):
    """``make(name, frames=SMALL)`` -> the folder of that terrain simulated with ``frames``
    evenly spaced scans, seed 0: made on first use, then shared by every test of the
    process (any package's tests: one simulation for many tests)."""
    from alte.sim import ensure_terrain

    def make(name: str, frames: int = SMALL):
        return ensure_terrain(name, small_data / f"f{frames}", seed=0, frames=frames)
    return make


@pytest.fixture(scope="session")
def uav_first_scans(tmp_path_factory: pytest.TempPathFactory):
    """The first 4 scans (0.3 s, consecutive) of ``sim_lan_1`` from the uav sensor: per-point
    time and an IMU, for LIO's tests of the pipeline: over 4 scans spread over the mission
    a LIO run integrated 45 s of IMU between them (5 CPU s; here 1 s)."""
    from support.missions import first_scans_folder

    from alte.sim.profile import PROFILES

    return first_scans_folder(tmp_path_factory.mktemp("uav_first") / "sim_lan_1", "sim_lan_1",
                              4, profile=PROFILES["uav"])
