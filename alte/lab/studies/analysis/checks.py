"""What every measured check yields: per-seed values and how to read them.

:class:`CheckValues` is the result of :func:`alte.lab.studies.analysis.measures.measure_check`;
:func:`case_rows` selects the rows a check reads and says what is missing.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import pandas as pd

from alte.errors import ParameterError
from alte.lab.studies.analysis.tradeoff import METRICS, mapper_title
from alte.lab.studies.thesis.numbers import TERRAIN_CASE

__all__ = ["ELAPSED", "STAT_COLUMNS", "CheckValues", "NoDataError", "case_rows", "name",
           "unit"]

#: Columns of :attr:`CheckValues.stats` (with ``low`` and ``high`` where a seed's value is
#: known only within bounds: a time, a tie of the thesis' rule).
STAT_COLUMNS = ["terrain", "level", "seed", "value"]
#: The time a claim names: the thesis' elapsed time.
ELAPSED = "elapsed_s"


class NoDataError(ParameterError):
    """The table cannot measure a check (missing rows, columns or settings)."""


@dataclass(frozen=True)
class CheckValues:
    """Per-seed values of one check and how to read them (see the module docstring).

    ``level_name`` is the column the levels are values of (equal-size or equal-fidelity
    reads), ``level_kind`` ``"size"`` or ``"fidelity"`` (empty without levels).
    ``time``: how a time was read (``"cost"``: judged on the machine-independent cost,
    with ``crosscheck`` the same statistic on the CPU time; ``"cpu"``: the CPU time
    within its spread; empty: no time). ``read_from_times``: which values are read
    depends on time readings (a CPU time, or the rows the thesis' rule picks), so which
    cells a run decides does too.
    """

    stats: pd.DataFrame
    what: str
    unit: str = ""
    ratio: bool = False
    threshold: float = 0.0
    relation: str = "better"
    band: float = 0.0
    level_name: str = ""
    level_kind: str = ""
    time: str = ""
    crosscheck: CheckValues | None = None
    read_from_times: bool = False


def name(mapper: str) -> str:
    """A mapper's display name."""
    return mapper_title(mapper)


def unit(metric: str) -> str:
    """A metric's unit (empty for counts)."""
    return METRICS.get(metric, ("", ""))[1]


def case_rows(table: pd.DataFrame, case: str, mappers: Sequence[str],
              columns: Sequence[str]) -> pd.DataFrame:
    """The rows of ``mappers`` on the terrains of ``case``, with values in ``columns``."""
    if "case" in table:
        in_case = table["case"] == case
    else:
        in_case = table["terrain"].map(TERRAIN_CASE) == case
    rows = table[in_case & table["mapper"].isin(mappers)]
    absent = [m for m in mappers if m not in set(rows["mapper"])]
    if absent:
        raise NoDataError(f"no rows of {', '.join(absent)} on the {case} terrains")
    missing = [c for c in columns if c not in rows or not rows[c].notna().any()]
    if missing:
        raise NoDataError(f"no values in column(s) {', '.join(missing)}")
    return rows
