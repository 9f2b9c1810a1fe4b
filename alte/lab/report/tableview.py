"""Tables as a reader sees them: headers with units, our values beside the thesis'.

:func:`table_view` turns a report CSV into a :class:`TableView`: every column
``x`` that has a ``thesis_x`` twin becomes one header "x [unit]" over two
sub-columns, *ours* and *thesis*; numbers get a sensible precision and thousands
separators; missing values show as a dash. ``key=True`` keeps only the columns a
reader compares (identifiers, parameters, paired metrics) and drops the rest, which
stay in the linked CSV.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import pandas as pd

from alte.lab.studies.analysis.tradeoff import METRICS, mapper_title
from alte.lab.studies.thesis.numbers import SWEEPS

__all__ = ["TableView", "cell_text", "header", "table_view"]

#: Columns that identify a row (shown first, in this order, when present).
IDENTITY = ("case", "terrain", "metric", "mapper", "params", "level", "thesis_params",
            "rule_on_thesis")
_PARAMETERS = tuple(dict.fromkeys(k for spec in SWEEPS.values() for p, *_ in spec["rows"]
                                  for k in p))
_UNITS = {"_m": "m", "_s": "s", "_bytes": "B"}
_WORDS = {"mean": "mean", "low": "CI low", "high": "CI high", "seeds": "seeds",
          "thesis_params": "thesis' parameters", "rule_on_thesis": "rule on thesis' rows",
          "params": "parameters"}


@dataclass(frozen=True)
class TableView:
    """Two header rows (``top``: text and span; ``sub``: under paired columns) and rows."""

    top: list[tuple[str, int]]
    sub: list[str]
    rows: list[list[str]]
    shape: tuple[int, int]


def header(column: str) -> str:
    """A column name in words with its unit: ``mhd_m`` -> ``MHD [m]``."""
    if column in METRICS:
        name, unit = METRICS[column]
        return f"{name} [{unit}]" if unit else name
    if column in _WORDS:
        return _WORDS[column]
    for suffix, unit in _UNITS.items():
        if column.endswith(suffix):
            return f"{column.removesuffix(suffix).replace('_', ' ')} [{unit}]"
    return column.replace("_", " ")


def cell_text(value: object, column: str = "") -> str:
    """One value as text: mapper names spelled out, numbers to 4 significant digits."""
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "\u2013"  # an en dash
    if isinstance(value, str) and column in ("mapper", "metric"):
        return mapper_title(value) if column == "mapper" else (
            header(value) if value in METRICS else value)
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, int) or (isinstance(value, float) and value.is_integer()
                                  and abs(value) >= 1000):
        return f"{int(value):,}"
    if isinstance(value, float):
        return f"{value:.4g}"
    return str(value)


def _columns(frame: pd.DataFrame, key: bool) -> list[str]:
    cols = [str(c) for c in frame.columns]
    paired = [c for c in cols if f"thesis_{c}" in cols]
    if not key:
        return [c for c in cols if not (c.startswith("thesis_") and c[7:] in paired)]
    ident = [c for c in IDENTITY if c in cols]
    params = [] if "params" in cols else [c for c in _PARAMETERS if c in cols]
    stats = [c for c in ("mean", "low", "high", "seeds") if c in cols]
    return ident + params + [c for c in paired if c not in ident] + stats


def table_view(frame: pd.DataFrame, *, key: bool = False, max_rows: int | None = None
               ) -> TableView:
    """The table as text (see the module docstring); ``max_rows`` keeps the first rows."""
    cols = [str(c) for c in frame.columns]
    chosen = _columns(frame, key)
    paired = {c for c in chosen if f"thesis_{c}" in cols and c not in IDENTITY}
    top = [(header(c), 2 if c in paired else 1) for c in chosen]
    sub = [s for c in chosen if c in paired for s in ("ours", "thesis")]
    shown = frame if max_rows is None else frame.head(max_rows)
    rows = []
    for record in shown.to_dict(orient="records"):
        row = []
        for c in chosen:
            row.append(cell_text(record[c], c))
            if c in paired:
                row.append(cell_text(record[f"thesis_{c}"], c))
        rows.append(row)
    return TableView(top, sub, rows, (len(frame), len(frame.columns)))
