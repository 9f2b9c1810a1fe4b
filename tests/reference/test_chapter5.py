"""Reference results: a quick chapter 5 run against its checked-in expected tables.

The run (``chapter5.yaml``: two terrains, four scans, three seeds, three settings per
mapper with the thesis' chosen ones) goes through the sweep engine, the trade-off table
and every claim of the catalogue, as the report does. Three tables are compared with
the files beside this module:

* ``chapter5_tradeoff.csv``: every trade-off row's map size and fidelity;
* ``chapter5_claims.csv``: every claim's verdict and what it depends on;
* ``chapter5_cells.csv``: the per-cell estimates and intervals behind the verdicts.

Nothing here is noisy except time: mapping time (``elapsed_s``) is left out of the rows,
and the verdicts and cells of checks that compare two mappers' times (CPU times) are
listed (``timed``) but not compared; so are those read at the row the thesis' rule
picks, whose criteria include the time. A time within one mapper is judged on its
machine-independent cost and compared like any other figure. Every other figure must
match to :data:`RTOL` and every text exactly. After a deliberate change, regenerate the
files with ``make reference`` (``pytest tests/reference --update-reference``) and read the
diff.

Why not to the last digit: on one machine the run is the same to the bit, but not across
CPUs (most likely the simulator's ray casting, open3d's ``RaycastingScene`` in float32,
whose vector code depends on the CPU: tests/README.md): on an AVX-512 machine, not the one
the files were written on, the distances moved by up to 8.8e-7 of their
value (``hd_m``; the cells' estimates and bounds by up to 2.5e-7), while every count,
size, verdict and outcome stayed the same. :data:`RTOL` leaves ten times that; a
deliberate change moves the figures it touches by far more. The cells' ``level`` (a
distance read off the data) is matched by its rank within its claim part and terrain,
and compared as a number.
"""

from __future__ import annotations

from dataclasses import fields
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from alte.lab.studies.analysis.evidence import cells_table, claims_table, evaluate_all
from alte.lab.studies.thesis.claims import CLAIMS, AllOf, Claim, Compare
from alte.lab.studies.tradeoff.grid import run_grid

HERE = Path(__file__).parent
SPEC = HERE / "chapter5.yaml"
KEYS = {"tradeoff": ["terrain", "mapper", "params", "seed"],
        "claims": ["id"], "cells": ["id", "part", "terrain", "level"]}
#: Trade-off columns compared (mapping time, the only noisy one, is left out).
ROW_COLUMNS = ["frames", "points", "basis_functions", "occupied_cells", "memory_bytes",
               "mhd_m", "hd_m", "mh_ab_m", "mh_ba_m", "accuracy_mean_m", "completeness",
               "height_rmse_m", "size_octaves", "cost", "cost_unit"]
CELL_COLUMNS = ["seeds", "estimate", "low", "high", "outcome", "timed"]
#: Relative (and absolute, for figures near zero) tolerance of every compared number
#: (module docstring: what moves across CPUs).
RTOL = 1e-5
TIME_COLUMNS = {"elapsed_s"}


def _timed(check: object) -> bool:
    """Does ``check`` read a measured time: the time of two mappers (CPU time, compared
    within its spread), or the row the thesis' rule picks (its criteria include the
    time, so the pick moves with the machine's load)? A check on the time within one
    mapper is judged on the mapper's machine-independent cost: compared like a size."""
    return (getattr(check, "at", None) == "rule"
            or (isinstance(check, Compare)
                and any(getattr(check, f.name) in TIME_COLUMNS for f in fields(check))))


def _timed_parts(claim: Claim) -> set[int]:
    parts = claim.check.parts if isinstance(claim.check, AllOf) else (claim.check,)
    return {i for i, part in enumerate(parts, 1) if _timed(part)}


def _tables(table: pd.DataFrame) -> dict[str, pd.DataFrame]:
    findings = evaluate_all(CLAIMS, table)
    timed = {c.id: _timed_parts(c) for c in CLAIMS}
    claims = claims_table(findings)[["id", "verdict", "depends_on"]].assign(
        timed=[bool(timed[i]) for i in claims_table(findings)["id"]])
    cells = cells_table(findings)
    cells = cells.assign(timed=[int(p) in timed[i] for i, p in zip(cells["id"], cells["part"],
                                                                   strict=True)])
    rows = table[KEYS["tradeoff"] + [c for c in ROW_COLUMNS if c in table]]
    return {"tradeoff": rows, "claims": claims,
            "cells": cells[KEYS["cells"] + CELL_COLUMNS]}


def _canonical(frame: pd.DataFrame, keys: list[str]) -> pd.DataFrame:
    """Sorted by its keys, the index reset, the level's NaN as empty text (a key)."""
    out = frame.copy()
    if "level" in out:
        out["level"] = [f"{float(v):.9g}" if pd.notna(v) and v != "" else ""
                        for v in out["level"]]
    if "part" in out:
        out["part"] = out["part"].astype(int)
    text = [c for c in out if not pd.api.types.is_numeric_dtype(out[c])
            and not pd.api.types.is_bool_dtype(out[c])]
    out[text] = out[text].fillna("")
    return out.sort_values(keys, kind="stable").reset_index(drop=True)


def _ranked(frame: pd.DataFrame, keys: list[str]) -> tuple[pd.DataFrame, list[str]]:
    """A table keyed on ``keys``, but for a ``level`` key: the level's rank within the rest
    of the key, the level itself a number (a distance measured on the data: module
    docstring)."""
    if "level" not in keys:
        return frame, keys
    rest = [k for k in keys if k != "level"]
    out = frame.copy()
    out["level"] = pd.to_numeric(out["level"].replace("", np.nan))
    ranks = out["level"].groupby([out[k] for k in rest]).rank(method="first")
    out["level_rank"] = ranks.fillna(0).astype(int)
    return out, [*rest, "level_rank"]


def _read(name: str) -> pd.DataFrame:
    return pd.read_csv(HERE / f"chapter5_{name}.csv", keep_default_na=False,
                       na_values=["nan"], dtype={"params": str, "depends_on": str})


def differences(name: str, expected: pd.DataFrame, actual: pd.DataFrame) -> list[str]:
    """Every difference between two tables, one readable line each (empty: equal).

    Rows are matched on :data:`KEYS`; numbers must agree to :data:`RTOL`, text exactly;
    in the cells and claims tables, rows marked ``timed`` are not compared.
    """
    exp, keys = _ranked(_canonical(expected, KEYS[name]), KEYS[name])
    act, _ = _ranked(_canonical(actual, KEYS[name]), KEYS[name])
    out = []
    if list(exp.columns) != list(act.columns):
        out.append(f"{name}: columns {list(act.columns)}, expected {list(exp.columns)}")
        return out
    exp["key"] = [tuple(r) for r in exp[keys].astype(str).to_numpy()]
    act["key"] = [tuple(r) for r in act[keys].astype(str).to_numpy()]
    out += [f"{name}: unexpected row {k}" for k in sorted(set(act["key"]) - set(exp["key"]))]
    out += [f"{name}: missing row {k}" for k in sorted(set(exp["key"]) - set(act["key"]))]
    both = exp.drop(columns=keys).merge(act.drop(columns=keys), on="key",
                                        suffixes=("", "_actual"))
    for key, row in zip(both["key"], (r for _, r in both.iterrows()), strict=True):
        if "timed" in row and (str(row["timed"]) == "True" or
                               str(row["timed_actual"]) == "True"):
            continue
        for column in (c for c in exp.columns if c not in (*keys, "key", "timed")):
            want, got = row[column], row[f"{column}_actual"]
            if not _same(want, got):
                out.append(f"{name} {key}: {column} = {got!r}, expected {want!r}")
    return out


def _same(want: object, got: object) -> bool:
    if pd.isna(want) or pd.isna(got):  # type: ignore[arg-type]
        return bool(pd.isna(want) and pd.isna(got))  # type: ignore[arg-type]
    if isinstance(want, (int, float, np.number)) and isinstance(got, (int, float, np.number)):
        return bool(np.isclose(float(got), float(want), rtol=RTOL, atol=RTOL))
    return str(want) == str(got)


@pytest.fixture(scope="module")
def actual(tmp_path_factory: pytest.TempPathFactory) -> dict[str, pd.DataFrame]:
    work = tmp_path_factory.mktemp("reference")
    grid = run_grid(SPEC, scheduler="serial", data_dir=str(work / "data"),
                    output=work / "runs", progress=False)
    assert not grid.failed, grid.failed
    return _tables(grid.table)


@pytest.mark.slow
@pytest.mark.parametrize("name", ["tradeoff", "claims", "cells"])
def test_the_quick_chapter5_run_matches_its_reference(actual, name, request):
    table = actual[name]
    path = HERE / f"chapter5_{name}.csv"
    if request.config.getoption("--update-reference"):
        _canonical(table, KEYS[name]).to_csv(path, index=False, float_format="%.12g",
                                             na_rep="nan")
    found = differences(name, _read(name), table)
    assert not found, (f"{len(found)} differences from {path.name} (after a deliberate "
                       "change: make reference, then read the diff):\n" + "\n".join(found[:60]))


def test_differences_name_what_changed():
    """The comparison itself: a changed figure, verdict or row is named; time is not."""
    rows = pd.DataFrame({"terrain": ["t", "t"], "mapper": ["m", "m"], "params": ["{}", "{}"],
                         "seed": [0, 1], "mhd_m": [0.5, 0.25], "basis_functions": [10, 12]})
    assert differences("tradeoff", rows, rows) == []
    doubled = rows.assign(mhd_m=rows["mhd_m"] * 2)
    assert differences("tradeoff", rows, doubled) == [
        "tradeoff ('t', 'm', '{}', '0'): mhd_m = 1.0, expected 0.5",
        "tradeoff ('t', 'm', '{}', '1'): mhd_m = 0.5, expected 0.25"]
    assert differences("tradeoff", rows, rows.assign(mhd_m=rows["mhd_m"] * (1 + 1e-6))) == []
    assert differences("tradeoff", rows, rows.iloc[:1].assign(mhd_m=0.5 * (1 + 1e-4))) == [
        "tradeoff: missing row ('t', 'm', '{}', '1')",
        "tradeoff ('t', 'm', '{}', '0'): mhd_m = 0.50005, expected 0.5"]
    assert differences("tradeoff", rows, rows.iloc[:1]) == [
        "tradeoff: missing row ('t', 'm', '{}', '1')"]
    claims = pd.DataFrame({"id": ["a", "b"], "verdict": ["holds", "depends"],
                           "depends_on": [np.nan, "terrain"], "timed": [False, True]})
    flipped = claims.assign(verdict=["does not hold", "holds"])
    assert differences("claims", claims, flipped) == [
        "claims ('a',): verdict = 'does not hold', expected 'holds'"]


def test_cells_match_levels_by_rank_and_compare_them_as_numbers():
    """A cell's level (a distance read off the data) that moved within the tolerance keeps
    its row; a level or an estimate beyond it is named, by the level's rank."""
    cells = pd.DataFrame({"id": ["c"] * 3, "part": [1] * 3, "terrain": ["t"] * 3,
                          "level": [0.901889733, 0.902378007, ""], "seeds": [3] * 3,
                          "estimate": [1.5, 2.5, 0.5], "low": [1.0] * 3, "high": [3.0] * 3,
                          "outcome": ["holds"] * 3, "timed": [False] * 3})
    moved = cells.assign(level=[0.901889752, 0.902378026, ""])
    assert differences("cells", cells, moved) == []
    off = moved.assign(level=[0.8, 0.902378026, ""], estimate=[1.5, 2.6, 0.5])
    assert differences("cells", cells, off) == [
        "cells ('c', '1', 't', '1'): level = 0.8, expected 0.901889733",
        "cells ('c', '1', 't', '2'): estimate = 2.6, expected 2.5"]
