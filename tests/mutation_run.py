"""Mutation testing of the verdict logic and the metrics, one module at a time (``make mutants``).

mutmut (``[tool.mutmut]`` in ``pyproject.toml``) runs, per mutant, only the tests its first
pass saw calling the mutated function; but that first pass runs every test of its
selection, and its selection is one list for the whole run. This driver gives each module
its own run with its own selection (:data:`MODULES`: the test files that state the
module's behaviour), in its own folder ``mutants/<name>/`` (mutmut keeps its copy of the
code and its results in ``mutants/<name>/mutants/``), so a module's run neither pays for
another module's tests nor loses its results when another selection changes.

Each run records its wall time and the machine's load average (sampled every 10 s) in
``mutants/<name>/run.json``; ``tests/mutation_score.py`` prints the score per module.
A second run continues where the last stopped (mutmut keeps every result and re-tests
only the functions whose code changed); a run narrowed to some mutants re-tests those
and keeps the others' earlier results (``mutants/<name>/results.json``). Usage, from
the repository::

    .venv/bin/python tests/mutation_run.py [NAME ...] [--mutants GLOB ...] [--max-children 2]

with NAME among :data:`MODULES` (default: all) and GLOB a mutmut mutant name pattern,
e.g. ``'alte.lab.studies.analysis.evidence.x__outcome*'``.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import subprocess
import sys
import threading
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
WORK = ROOT / "mutants"

#: name -> (the module mutated, the pytest selection whose tests may kill its mutants).
MODULES: dict[str, tuple[str, tuple[str, ...]]] = {
    "hausdorff": ("alte/metrics/hausdorff.py", (
        "tests/metrics/test_metrics.py", "-k", "hausdorff or directed or to_the_last_bit")),
    "truth": ("alte/metrics/truth.py", (
        "tests/metrics/test_metrics.py", "tests/metrics/test_truth.py",
        "tests/metrics/test_truth_cases.py", "-k",
        "not hausdorff and not directed and not to_the_last_bit")),
    "freespace": ("alte/metrics/freespace.py", (
        "tests/metrics/test_metrics.py", "tests/metrics/test_truth.py", "-k", "free")),
    "trajectory": ("alte/metrics/trajectory.py", ("tests/metrics/test_trajectory.py",)),
    "checks": ("alte/lab/studies/analysis/checks.py", (
        "tests/lab/studies/analysis/test_checks.py", "tests/lab/studies/analysis/test_verdicts.py",
        "tests/lab/studies/analysis/test_measures.py",
        "tests/lab/studies/analysis/test_evidence.py")),
    "comparisons": ("alte/lab/studies/analysis/comparisons.py", (
        "tests/lab/studies/analysis/test_verdicts.py",
        "tests/lab/studies/analysis/test_measures.py",
        "tests/lab/studies/analysis/test_evidence.py",
        "tests/lab/studies/analysis/test_comparisons_cases.py")),
    "measures": ("alte/lab/studies/analysis/measures.py", (
        "tests/lab/studies/analysis/test_verdicts.py",
        "tests/lab/studies/analysis/test_measures.py",
        "tests/lab/studies/analysis/test_evidence.py",
        "tests/lab/studies/analysis/test_conditions.py",
        "tests/lab/studies/analysis/test_measures_cases.py")),
    "evidence": ("alte/lab/studies/analysis/evidence.py", (
        "tests/lab/studies/analysis/test_verdicts.py",
        "tests/lab/studies/analysis/test_evidence.py",
        "tests/lab/studies/analysis/test_evidence_tables.py",
        "tests/lab/studies/analysis/test_conditions.py")),
    "wording": ("alte/lab/studies/analysis/wording.py", (
        "tests/lab/studies/analysis/test_verdicts.py",
        "tests/lab/studies/analysis/test_evidence.py",
        "tests/lab/studies/analysis/test_evidence_tables.py")),
    "tradeoff": ("alte/lab/studies/analysis/tradeoff.py", (
        "tests/lab/studies/analysis/test_tradeoff.py",
        "tests/lab/studies/analysis/test_verdicts.py",
        "tests/lab/studies/analysis/test_measures.py",
        "tests/lab/studies/analysis/test_tradeoff_cases.py")),
    "claims": ("alte/lab/studies/thesis/claims/__init__.py",
    ("tests/lab/studies/thesis/test_claims.py",)),
}


def _workspace(name: str) -> Path:
    """``mutants/<name>/`` with the code, the tests and the settings linked in."""
    folder = WORK / name
    folder.mkdir(parents=True, exist_ok=True)
    for item in ("alte", "tests", "pyproject.toml"):
        link = folder / item
        if not link.is_symlink():
            link.symlink_to(ROOT / item)
    return folder


def _one(name: str, globs: list[str], children: int) -> int:
    """Run mutmut on one module in its workspace (in this process: mutmut's state is global)."""
    from mutmut import configuration
    from mutmut.__main__ import _run

    module, selection = MODULES[name]
    os.chdir(_workspace(name))
    # forked test processes inherit this one: keep numba's thread pool out of them
    os.environ.setdefault("NUMBA_NUM_THREADS", "1")
    base = configuration._load_config()
    configuration._config = dataclasses.replace(
        base, only_mutate=[module], pytest_add_cli_args_test_selection=list(selection))
    _run(globs, children)
    return 0


class _Load:
    """The 1-minute load average, sampled every 10 s while a run lasts."""

    def __init__(self) -> None:
        self.samples: list[float] = [os.getloadavg()[0]]
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._sample, daemon=True)

    def _sample(self) -> None:
        while not self._stop.wait(10.0):
            self.samples.append(os.getloadavg()[0])

    def __enter__(self) -> _Load:
        self._thread.start()
        return self

    def __exit__(self, *_: object) -> None:
        self._stop.set()
        self._thread.join()


def _meta(name: str) -> Path:
    return WORK / name / "mutants" / (MODULES[name][0] + ".meta")


def _keep_results(name: str) -> None:
    """Carry every mutant's latest result over runs in ``results.json``.

    A run narrowed to some mutants (``--mutants``) leaves the others unchecked in mutmut's
    ``.meta``; their earlier results (from tests that are all still there) are put back,
    and a mutant run again gets its new result.
    """
    meta, kept = _meta(name), WORK / name / "results.json"
    if not meta.exists():
        return
    data = json.loads(meta.read_text())
    codes = json.loads(kept.read_text()) if kept.exists() else {}
    codes.update({k: v for k, v in data["exit_code_by_key"].items() if v is not None})
    kept.write_text(json.dumps(codes, indent=0, sort_keys=True) + "\n")
    data["exit_code_by_key"] = {k: codes.get(k) for k in data["exit_code_by_key"]}
    meta.write_text(json.dumps(data))


def run(names: list[str], globs: list[str], children: int) -> int:
    """Each module in a fresh process; its time and load written to ``run.json``."""
    failed = 0
    for name in names:
        _keep_results(name)
        argv = [sys.executable, __file__, "--one", name, "--max-children", str(children),
                *(f"--mutants={g}" for g in globs)]
        start = time.monotonic()
        with _Load() as load:
            code = subprocess.call(argv, cwd=ROOT)
        record = {"module": MODULES[name][0], "selection": list(MODULES[name][1]),
                  "mutants": globs, "max_children": children, "exit_code": code,
                  "wall_s": round(time.monotonic() - start, 1),
                  "finished": time.strftime("%Y-%m-%d %H:%M:%S"),
                  "load_mean": round(sum(load.samples) / len(load.samples), 1),
                  "load_max": round(max(load.samples), 1), "cores": os.cpu_count()}
        (WORK / name / "run.json").write_text(json.dumps(record, indent=1) + "\n")
        _keep_results(name)
        print(f"{name}: exit {code}, {record['wall_s']:.0f} s, load average "
              f"{record['load_mean']} (max {record['load_max']}) on {os.cpu_count()} cores")
        failed |= code != 0
    return int(failed)


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("names", nargs="*", help=f"modules to mutate: {', '.join(MODULES)} "
                        "(default: all)")
    parser.add_argument("--mutants", action="append", default=[],
                        help="mutmut mutant name or glob (repeatable)")
    parser.add_argument("--max-children", type=int, default=2)
    parser.add_argument("--one", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.one:
        return _one(args.one, args.mutants, args.max_children)
    unknown = [n for n in args.names if n not in MODULES]
    if unknown:
        parser.error(f"unknown module(s) {', '.join(unknown)}; known: {', '.join(MODULES)}")
    return run(args.names or list(MODULES), args.mutants, args.max_children)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
