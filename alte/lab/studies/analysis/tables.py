"""Tables 5.1-5.12 from measurements, the thesis' comparison rule, and trend checks.

The comparison rule (thesis 5.2.2, "Comparison") as code: every criterion counts the
same except HD, which enters only as outlier rejection (HD - MHD, "the closer HD is to
MHD, the better"). So the criteria are elapsed time, basis functions, MHD and HD - MHD,
all lower-is-better; each is min-max normalised over the sweep (0 = best row, 1 =
worst), the four are summed and the lowest sum wins (:func:`best_row`).
Applied to the thesis' own numbers the rule reproduces its 3D-ALTE choice (table 5.11)
but not the other three: the thesis' tables are not consistent with any one rule (its
2D-ALTE pick, row 4 of table 5.9, is beaten by row 1 on time and basis functions at
equal HD and MHD). :func:`comparison_table` prints both choices side by side.

On our maps the time is the mapper's CPU seconds (``map_cpu_s``, the least of repeated
runs; :func:`rule_criteria`), and it is known only within its spread
(:func:`alte.lab.studies.analysis.uncertainty.time_spreads`). :func:`rule_picks` keeps every row
that
no other row beats whatever the times within their spreads: one row, or a *tie* of rows
the rule cannot separate, all of which the comparison tables show. Where one map is
needed, :func:`rule_pick` breaks a tie by the machine-independent cost in place of the
time (the same mapper's rows, so one unit), never by a time reading.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from alte.errors import ParameterError
from alte.fsutil import atomic_path
from alte.lab.studies.analysis.uncertainty import time_spreads
from alte.lab.studies.thesis.numbers import COMPARISONS, POINT_CLOUDS, SWEEPS, sweep_table

__all__ = ["COMPARISON_TRENDS", "SWEEP_TRENDS", "THESIS_CRITERIA", "TIME_COLUMN", "best_row",
           "comparison_scores", "comparison_table", "point_cloud_table", "rule_criteria",
           "rule_pick", "rule_picks", "thesis_metrics", "write_csv",
           "write_table"]

#: The criteria of the comparison rule, all lower-is-better, equally weighted.
THESIS_CRITERIA: tuple[str, ...] = ("elapsed_s", "basis_functions", "mhd_m", "hd_minus_mhd_m")
#: The time of our maps the rule weighs: the mapper's CPU seconds, least of repeats.
TIME_COLUMN = "map_cpu_s"
_TIMES = ("elapsed_s", TIME_COLUMN)

_THESIS_COLS = {"elapsed_s": "thesis_elapsed_s", "basis_functions": "thesis_basis_functions",
                "hd_m": "thesis_hd_m", "mhd_m": "thesis_mhd_m"}

#: Trends the thesis states for each sweep: (statement, parameter, metric, expected sign).
SWEEP_TRENDS: dict[int, list[tuple[str, str, str, int]]] = {
    7: [("elapsed time falls as max points per cell rises", "max_points", "elapsed_s", -1),
        ("basis functions fall as max points per cell rises", "max_points", "basis_functions",
         -1),
        ("MHD rises as the map gets coarser (more max points)", "max_points", "mhd_m", 1)],
    8: [("elapsed time rises with resolution", "resolution", "elapsed_s", 1),
        ("basis functions rise with resolution", "resolution", "basis_functions", 1),
        ("HD falls as resolution rises", "resolution", "hd_m", -1),
        ("MHD falls as resolution rises", "resolution", "mhd_m", -1)],
    9: [("elapsed time rises with max_res", "max_res", "elapsed_s", 1),
        ("basis functions rise with max_res", "max_res", "basis_functions", 1),
        ("elapsed time rises with kappa", "kappa", "elapsed_s", 1)],
    12: [("elapsed time rises with max_res", "max_res", "elapsed_s", 1),
         ("basis functions rise with max_res", "max_res", "basis_functions", 1),
         ("MHD falls as max_res rises", "max_res", "mhd_m", -1)],
}

#: Comparison claims of tables 5.10/5.11: (statement, lower mapper, higher mapper, metric).
COMPARISON_TRENDS: dict[int, list[tuple[str, str, str, str]]] = {
    10: [("2D-ALTE has fewer basis functions than Quadtree", "alte2d", "quadtree",
          "basis_functions"),
         ("2D-ALTE has a lower MHD than Quadtree", "alte2d", "quadtree", "mhd_m"),
         ("Quadtree rejects outliers better (smaller HD - MHD)", "quadtree", "alte2d",
          "hd_minus_mhd_m")],
    11: [("Octomap maps faster than 3D-ALTE", "octomap", "alte3d", "elapsed_s"),
         ("3D-ALTE has fewer basis functions than Octomap", "alte3d", "octomap",
          "basis_functions"),
         ("3D-ALTE has a lower MHD than Octomap", "alte3d", "octomap", "mhd_m"),
         ("3D-ALTE rejects outliers better (smaller HD - MHD)", "alte3d", "octomap",
          "hd_minus_mhd_m")],
}


def thesis_metrics(number: int) -> pd.DataFrame:
    """Sweep table 5.``number`` of the thesis with our metric column names."""
    table = sweep_table(number).rename(columns={v: k for k, v in _THESIS_COLS.items()})
    table["hd_minus_mhd_m"] = table["hd_m"] - table["mhd_m"]
    return table


def comparison_scores(table: pd.DataFrame,
                      criteria: Sequence[str] = THESIS_CRITERIA) -> NDArray[np.float64]:
    """Equal-weight score per row: the sum of min-max normalised criteria (lower is better)."""
    missing = [c for c in criteria if c not in table.columns]
    if missing:
        raise ParameterError(f"comparison rule: table lacks column(s) {', '.join(missing)}")
    if len(table) == 0:
        raise ParameterError("comparison rule: the table has no rows")
    values = table[list(criteria)].to_numpy(dtype=np.float64)
    valid = np.isfinite(values).all(axis=1)
    if not valid.any():
        raise ParameterError("comparison rule: no row has every criterion (empty maps?)")
    lo, hi = values[valid].min(axis=0), values[valid].max(axis=0)
    norm = (values - lo) / np.where(hi > lo, hi - lo, 1.0)
    return np.where(valid, norm.sum(axis=1), np.inf)


def best_row(table: pd.DataFrame, criteria: Sequence[str] = THESIS_CRITERIA) -> int:
    """Position of the row the comparison rule picks on the readings as they are (first
    on equal scores; rows with a missing criterion, e.g. NaN HD of an empty map, never
    win). :func:`rule_picks` takes the time's spread into account."""
    return int(np.argmin(comparison_scores(table, criteria)))


def rule_criteria(table: pd.DataFrame) -> tuple[str, ...]:
    """The rule's criteria for ``table``: the time as the mapper's CPU seconds where the
    table has them (our maps), else the elapsed time (the thesis' numbers)."""
    if TIME_COLUMN in table:
        return (TIME_COLUMN, *THESIS_CRITERIA[1:])
    return THESIS_CRITERIA


def _surely_beaten(fixed: NDArray[np.float64], times: NDArray[np.float64],
                   spreads: NDArray[np.float64]) -> NDArray[np.bool_]:
    """``out[i, j]``: row i's score is below row j's whatever the times within their
    spreads (``fixed``: the score without the time term). The time term of a row is
    (t - min t) / (max t - min t) over perturbed times; its largest difference i - j
    puts t_i at its top and t_j at its bottom, over the narrowest range they allow when
    that difference is positive, the widest when it is negative."""
    top, bottom = times * np.exp(spreads), times * np.exp(-spreads)
    gap = top[:, None] - bottom[None, :]
    widest = top.max() - bottom.min()
    narrowest = np.maximum(bottom.max() - top.min(), gap)
    with np.errstate(divide="ignore", invalid="ignore"):
        worst = np.where(gap > 0, gap / narrowest, gap / widest)
    worst = np.nan_to_num(worst, nan=0.0)
    return np.asarray(fixed[:, None] - fixed[None, :] + worst < -1e-12)


def rule_picks(table: pd.DataFrame, criteria: Sequence[str] | None = None,
               ) -> NDArray[np.intp]:
    """Positions (ascending) of the rows the rule cannot tell from the best one: every
    row with all criteria that no other row beats whatever the times within their
    spreads (:func:`~alte.lab.studies.analysis.uncertainty.time_spreads`). One position, or a
    tie."""
    chosen = tuple(criteria or rule_criteria(table))
    scores = comparison_scores(table, chosen)
    valid = np.flatnonzero(np.isfinite(scores))
    timed = [c for c in chosen if c in _TIMES]
    if not timed:
        return np.asarray(valid[scores[valid] == scores[valid].min()])
    times = table[timed[0]].to_numpy(dtype=np.float64)[valid]
    lo, hi = times.min(), times.max()
    fixed = scores[valid] - (times - lo) / (hi - lo if hi > lo else 1.0)
    beaten = _surely_beaten(fixed, times, time_spreads(table.iloc[valid]))
    return valid[~beaten.any(axis=0)]


def rule_pick(table: pd.DataFrame, criteria: Sequence[str] | None = None) -> int:
    """One row of :func:`rule_picks`: of a tie, the best by the rule with the time replaced
    by the machine-independent ``cost`` (the first, where the table has no cost)."""
    picks = rule_picks(table, criteria)
    chosen = tuple(criteria or rule_criteria(table))
    if len(picks) == 1 or "cost" not in table or table["cost"].isna().any():
        return int(picks[0])
    by_cost = tuple("cost" if c in _TIMES else c for c in chosen)
    return int(picks[np.argmin(comparison_scores(table, by_cost)[picks])])


def _params_text(params: Mapping[str, object]) -> str:
    return ", ".join(f"{k}={v}" for k, v in params.items())


def comparison_table(number: int, sweeps: Mapping[str, pd.DataFrame]) -> pd.DataFrame:
    """Table 5.10 or 5.11: per mapper our best row by the rule (every row of a tie, with
    ``rule_pick`` "tie"; else "best") beside the thesis' choice.

    ``sweeps`` maps mapper name to its sweep table from
    :func:`alte.lab.studies.experiments.sweep`. ``rule_score`` is the row's score on the
    readings; ``rule_on_thesis`` is what the same rule picks from the thesis' own numbers.
    """
    if number not in COMPARISONS:
        raise ParameterError(f"table 5.{number} is not a comparison; those are 10 and 11")
    rows = []
    for mapper, (table, thesis_row) in COMPARISONS[number].items():
        if mapper not in sweeps:
            raise ParameterError(f"table 5.{number} needs the {mapper} sweep (table 5.{table})")
        ours = sweeps[mapper]
        picks, scores = rule_picks(ours), comparison_scores(ours, rule_criteria(ours))
        theirs = thesis_metrics(table)
        params = SWEEPS[table]["rows"]
        chosen = theirs.iloc[thesis_row]
        thesis = {"thesis_params": _params_text(params[thesis_row][0]),
                  **{v: chosen[k] for k, v in _THESIS_COLS.items()},
                  "thesis_hd_minus_mhd_m": chosen["hd_minus_mhd_m"],
                  "rule_on_thesis": _params_text(params[best_row(theirs)][0])}
        for at in picks:
            pick = ours.iloc[at]
            rows.append({"mapper": mapper,
                         "params": _params_text(params[int(pick["thesis_row"])][0]),
                         "rule_pick": "tie" if len(picks) > 1 else "best",
                         "rule_score": float(scores[at]),
                         **{k: v for k, v in pick.items() if not str(k).startswith("thesis_")},
                         **thesis})
    return pd.DataFrame(rows)


def point_cloud_table(number: int, name: str, frames: int, points: int) -> pd.DataFrame:
    """Table 5.5 or 5.6: frames and points of our registered cloud beside the thesis'."""
    if number not in POINT_CLOUDS:
        raise ParameterError(f"table 5.{number} is not a point-cloud table; those are 5 and 6")
    ref = POINT_CLOUDS[number]
    return pd.DataFrame([{"terrain": name, "frames": frames, "points": points,
                          "thesis_terrain": ref["terrain"], "thesis_frames": ref["frames"],
                          "thesis_points": ref["points"]}])


def write_csv(table: pd.DataFrame, out_dir: str | os.PathLike[str], name: str,
              overwrite: bool = False) -> Path:
    """Write a report table as ``out_dir/<name>.csv``: atomic, 6 significant digits.

    Refuses to overwrite unless asked. The one writer of every table in the report.
    """
    path = Path(out_dir) / f"{name}.csv"
    with atomic_path(path, overwrite=overwrite) as tmp:
        table.to_csv(tmp, index=False, float_format="%.6g")
    return path


def write_table(table: pd.DataFrame, out_dir: str | os.PathLike[str], number: int,
                overwrite: bool = False) -> Path:
    """Write ``out_dir/table_5_<number>.csv`` (see :func:`write_csv`)."""
    return write_csv(table, out_dir, f"table_5_{number}", overwrite)
