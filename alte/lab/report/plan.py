"""What ``alte report`` runs, as data: one :class:`Entry` per notebook run.

An entry names a notebook and the parameters it gets in quick and full mode
(``None`` = not run in that mode); each study declares its own (its folder's ``report``
module) and :data:`PLAN` only collects them. :func:`build_plan` turns entries into concrete
:class:`Run` objects, checked against the parameters each notebook declares
(``papermill.inspect_notebook``), so a misspelt parameter is an error, never ignored.
"""

from __future__ import annotations

import ast
import json
import os
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import ClassVar

from alte.errors import ParameterError, ReportError
from alte.lab.entry import QUICK_FRAMES, Entry
from alte.lab.studies.landing import report as landing
from alte.lab.studies.planning import report as planning
from alte.lab.studies.realdata import report as realdata
from alte.lab.studies.sensor.report import SENSOR_SEEDS, SENSOR_SEEDS_ALL
from alte.lab.studies.sweep import report as sweep
from alte.lab.studies.thesis import report as thesis
from alte.lab.studies.thesis.report import TERRAINS
from alte.lab.studies.tradeoff import report as tradeoff
from alte.params import Record, key_values, param
from alte.types import JSON, JSONDict, JSONMap

__all__ = [
    "PLAN",
    "QUICK_FRAMES",
    "RUNNER_PARAMETERS",
    "SENSOR_SEEDS",
    "SENSOR_SEEDS_ALL",
    "TERRAINS",
    "Entry",
    "Run",
    "build_plan",
    "load_plan",
    "notebook_parameters",
    "parse_param",
]

#: Parameters the runner sets itself (output locations); users cannot override them.
RUNNER_PARAMETERS: tuple[str, ...] = ("OUT_DIR", "TABLES_DIR", "DATA_DIR")

#: The report, collected from each study's ``report`` module: chapters 2 and 3 once,
#: chapter 4 once per terrain, chapter 5, then the chapters beyond the thesis. Quick
#: mode keeps the notebooks' small defaults except a common ``FRAMES``.
PLAN: tuple[Entry, ...] = (*thesis.ENTRIES, *tradeoff.ENTRIES, *sweep.ENTRIES,
                           *realdata.ENTRIES, *landing.ENTRIES, *planning.ENTRIES)


@dataclass(frozen=True)
class Run(Record):
    """A concrete run: notebook path, user parameters and the terrains it needs."""

    OWNER: ClassVar[str] = "run"
    name: str = param("", help="the run's name")
    notebook: Path = param(Path(), help="the notebook's path")
    parameters: JSONMap = field(default_factory=dict)
    defaults: JSONMap = field(default_factory=dict)
    terrains: tuple[str, ...] = param((), help="the terrains it needs")
    first: bool = param(False, help="started before the others (:attr:`Entry.first`)")

    def value(self, name: str) -> JSON:
        """The value ``name`` takes in this run (planned, else the notebook's default)."""
        return self.parameters.get(name, self.defaults.get(name))


def parse_param(text: str) -> tuple[str, JSON]:
    """``"NAME=VALUE"`` -> (NAME, value); VALUE is a Python literal or else a string."""
    try:
        ((name, raw),) = key_values([text]).items()
        if not name.isidentifier():
            raise ParameterError(f"{name!r} is not a name")
    except ParameterError as err:
        raise ParameterError(f"notebook parameter {text!r}: expected NAME=VALUE",
                             setting="report.param") from err
    try:
        value: JSON = ast.literal_eval(raw)
    except (ValueError, SyntaxError):
        value = raw
    return name, value


def notebook_parameters(path: str | os.PathLike[str]) -> JSONDict:
    """The parameters a notebook's ``parameters`` cell declares, with their default values."""
    import papermill

    path = Path(path)
    if not path.is_file():
        raise ReportError(f"notebook {path} does not exist")
    try:
        inferred = papermill.inspect_notebook(str(path))
    except Exception as err:
        raise ReportError(f"notebook {path}: cannot read its parameters ({err})") from err
    out: JSONDict = {}
    for name, info in inferred.items():
        try:
            out[name] = ast.literal_eval(info["default"])
        except (ValueError, SyntaxError):
            out[name] = info["default"]
    return out


def load_plan(path: str | os.PathLike[str]) -> tuple[Entry, ...]:
    """Read a plan from JSON: a list of objects with the :class:`Entry` fields."""
    path = Path(path)
    try:
        items = json.loads(path.read_text())
        if not isinstance(items, list):
            raise TypeError("expected a list of entries")
        return tuple(Entry.parse(item) for item in items)
    except (OSError, ValueError, TypeError, AttributeError, ParameterError) as err:
        raise ReportError(f"plan {path}: {err}") from err


def _select(entries: Sequence[Entry], quick: bool, only: Iterable[str]) -> list[Entry]:
    mode = [e for e in entries if (e.quick if quick else e.full) is not None]
    only = list(only)
    if not only:
        return mode
    known = {e.name for e in mode} | {Path(e.notebook).stem for e in mode}
    unknown = [name for name in only if name not in known]
    if unknown:
        raise ParameterError(f"run {', '.join(unknown)}: no such run; valid: "
                             f"{', '.join(sorted(known))}", setting="report.only")
    return [e for e in mode if e.name in only or Path(e.notebook).stem in only]


def _check_overrides(overrides: JSONMap, declared: Mapping[str, Iterable[str]]) -> None:
    fixed = sorted(set(overrides) & set(RUNNER_PARAMETERS))
    if fixed:
        raise ParameterError(f"notebook parameter {', '.join(fixed)}: set by the runner (from "
                             "its output and data folders)", setting="report.param")
    valid = set().union(*declared.values()) - set(RUNNER_PARAMETERS) if declared else set()
    unknown = sorted(set(overrides) - valid)
    if unknown:
        raise ParameterError(f"unknown notebook parameter {', '.join(unknown)}; valid parameters: "
                             f"{', '.join(sorted(valid)) or '(none)'}")


def _terrains(entry: Entry, params: JSONMap) -> tuple[str, ...]:
    terrain = params.get("TERRAIN")
    named = (terrain,) if isinstance(terrain, str) and terrain else ()
    return tuple(dict.fromkeys((*named, *entry.terrains)))


def build_plan(entries: Sequence[Entry] = PLAN, *, quick: bool,
               notebooks_dir: str | os.PathLike[str], only: Iterable[str] = (),
               overrides: JSONMap | None = None) -> list[Run]:
    """Concrete runs for the mode, ``--only`` selection and ``--param`` overrides.

    Every plan parameter must be declared by its notebook and every override by at
    least one selected notebook (else :class:`ParameterError` listing the valid names).
    """
    overrides = dict(overrides or {})
    selected = _select(entries, quick, only)
    declared = {e.notebook: notebook_parameters(Path(notebooks_dir) / e.notebook)
                for e in selected}
    _check_overrides(overrides, {nb: list(p) for nb, p in declared.items()})
    runs = []
    for entry in selected:
        defaults = declared[entry.notebook]
        planned = dict((entry.quick if quick else entry.full) or {})
        bad = sorted(set(planned) - set(defaults))
        if bad:
            raise ParameterError(f"plan entry {entry.name}: {entry.notebook} has no parameter "
                                 f"{', '.join(bad)}; valid parameters: "
                                 f"{', '.join(sorted(defaults))}")
        if "OUT_DIR" not in defaults:
            raise ReportError(f"notebook {entry.notebook} declares no OUT_DIR parameter")
        planned |= {k: v for k, v in overrides.items() if k in defaults}
        runs.append(Run(entry.name, Path(notebooks_dir) / entry.notebook, planned,
                        defaults, _terrains(entry, {**defaults, **planned}), entry.first))
    return runs
