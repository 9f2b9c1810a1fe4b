"""Qualitative tables 5.1-5.4 filled from measurements where one exists.

Each criterion gets our label, the measured value behind it, its source
("measured: ..." or "thesis") and the thesis' label. The measurements:

* recursiveness: the mapper supports incremental updates (``Mapper.incremental``);
* adaptability: octaves spanned by the cell edges of the chosen map, log2(max/min);
  >= 3 High, >= 1 Mid, else Low;
* robustness: spread of MHD across the sweep (coefficient of variation std/mean);
  < 0.1 High, < 0.25 Mid, else Low;
* outlier rejection: HD - MHD of the chosen map, relative to the better mapper of the
  pair: <= 1.25x High, <= 2x Mid, else Low;
* map quality (5.3): 2D completeness against the true top surface; >= 0.8 High,
  >= 0.5 Mid, else Low;
* map size (5.4): basis functions relative to the larger map of the pair: >= 0.5 High,
  >= 0.1 Mid, else Low;
* overhanging structures (5.4): completeness on the ``overhang`` objects of sim_nav_2;
  >= 0.5 Yes.

Development, obstacle identification and free-space mapping have no measurement here
and come from the thesis, marked as such. (Free space is not measurable from the cells
alone: 3D-ALTE's unoccupied leaves are "not occupied", not observed-free; the metric
``free_truly_free_share`` in the sweep tables is meaningful for Octomap only.)
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike

from alte.lab.studies.analysis.tables import rule_pick
from alte.lab.studies.experiments import Measured, measure, reference_of
from alte.lab.studies.thesis.numbers import QUALITATIVE
from alte.metrics.maps import TruthSettings
from alte.pipeline import Registered

__all__ = ["MEASURES", "Inputs", "class_completeness", "qualitative_inputs", "qualitative_table"]


@dataclass(frozen=True)
class Inputs:
    """What the measured criteria read of one mapper: the metrics of its ``best`` (chosen)
    map, the MHD of every row of its sweep, whether it inserts incrementally and its
    completeness on the overhang objects of sim_nav_2 (NaN: not measured)."""

    best: Mapping[str, float]
    sweep_mhd: ArrayLike
    incremental: bool
    overhang_completeness: float = float("nan")


def _grade(value: float, high: float, mid: float, reverse: bool = False) -> str:
    if not np.isfinite(value):
        return "n/a"
    if reverse:
        return "High" if value < high else "Mid" if value < mid else "Low"
    return "High" if value >= high else "Mid" if value >= mid else "Low"


def _recursive(m: Inputs, _pair: Mapping[str, Inputs]) -> tuple[str, float]:
    return ("Yes" if m.incremental else "No"), float(m.incremental)


def _adaptability(m: Inputs, _pair: Mapping[str, Inputs]) -> tuple[str, float]:
    v = float(m.best.get("size_octaves", np.nan))
    return _grade(v, 3.0, 1.0), v


def _robustness(m: Inputs, _pair: Mapping[str, Inputs]) -> tuple[str, float]:
    mhd = np.asarray(m.sweep_mhd, dtype=np.float64)
    v = float(mhd.std() / mhd.mean()) if mhd.size > 1 and mhd.mean() > 0 else np.nan
    return _grade(v, 0.1, 0.25, reverse=True), v


def _outliers(m: Inputs, pair: Mapping[str, Inputs]) -> tuple[str, float]:
    v = float(m.best["hd_minus_mhd_m"])
    best = min(float(p.best["hd_minus_mhd_m"]) for p in pair.values())
    ratio = v / best if best > 0 else (1.0 if v == 0 else np.inf)
    return _grade(ratio, 1.25, 2.0, reverse=True), v


def _quality(m: Inputs, _pair: Mapping[str, Inputs]) -> tuple[str, float]:
    v = float(m.best.get("completeness", np.nan))
    return _grade(v, 0.8, 0.5), v


def _size(m: Inputs, pair: Mapping[str, Inputs]) -> tuple[str, float]:
    v = float(m.best["basis_functions"])
    return _grade(v / max(float(p.best["basis_functions"]) for p in pair.values()), 0.5,
                  0.1), v


def _overhang(m: Inputs, _pair: Mapping[str, Inputs]) -> tuple[str, float]:
    v = float(m.overhang_completeness)
    return ("n/a" if not np.isfinite(v) else "Yes" if v >= 0.5 else "No"), v


#: Criterion -> (how it is measured, function of (this mapper's inputs, the pair's)).
MEASURES: dict[str, tuple[str, Callable[[Inputs, Mapping[str, Inputs]], tuple[str, float]]]] = {
    "recursiveness": ("incremental insert", _recursive),
    "adaptability": ("cell-size octaves", _adaptability),
    "robustness": ("MHD coefficient of variation over the sweep", _robustness),
    "outlier_rejection": ("HD - MHD of the chosen map (m)", _outliers),
    "map_quality": ("2D completeness vs true top surface", _quality),
    "map_size": ("basis functions of the chosen map", _size),
    "overhanging_structures": ("completeness on sim_nav_2 overhangs", _overhang),
}


def qualitative_table(number: int, inputs: Mapping[str, Inputs]) -> pd.DataFrame:
    """Table 5.``number`` (1-4) from ``inputs``: per mapper a mapping with ``best`` (metrics
    of the chosen map), ``sweep_mhd`` (MHD of every sweep row), ``incremental`` and, for
    table 5.4, ``overhang_completeness``. Criteria without a measurement (or whose
    measurement is missing) fall back to the thesis' label."""
    rows = []
    for mapper, criteria in QUALITATIVE[number].items():
        row: dict[str, str | float] = {"mapper": mapper}
        for crit, thesis_label in criteria.items():
            label, value, source = thesis_label, np.nan, "thesis"
            if crit in MEASURES and mapper in inputs:
                what, fn = MEASURES[crit]
                label, value = fn(inputs[mapper], inputs)
                source = f"measured: {what}"
                if label == "n/a":
                    label, source = thesis_label, f"thesis (no measurement: {what})"
            row.update({crit: label, f"{crit}_value": value, f"{crit}_source": source,
                        f"thesis_{crit}": thesis_label})
        rows.append(row)
    return pd.DataFrame(rows)


def qualitative_inputs(sweeps: Mapping[str, tuple[pd.DataFrame, Sequence[Measured]]],
                       overhang: Mapping[str, float] | None = None) -> dict[str, Inputs]:
    """Inputs of :func:`qualitative_table` from :func:`alte.lab.studies.experiments.sweep` results.

    The chosen map of each sweep is the row the comparison rule picks (of a tie, by the
    cost: :func:`alte.lab.studies.analysis.tables.rule_pick`); ``overhang``
    maps mapper name to its completeness on the overhang objects of sim_nav_2.
    """
    out = {}
    for mapper, (table, runs) in sweeps.items():
        run = runs[rule_pick(table)]
        out[mapper] = Inputs(run.metrics.flat(), table["mhd_m"].to_numpy(),
                             bool(type(run.mapper).incremental),
                             (overhang or {}).get(mapper, np.nan))
    return out


def class_completeness(data: Registered,
                       sweeps: Mapping[str, tuple[pd.DataFrame, Sequence[Measured]]],
                       truth: TruthSettings, cls: str = "overhang") -> dict[str, float]:
    """Map ``data`` (e.g. sim_nav_2) with each sweep's chosen parameters and return the
    completeness on objects of class ``cls`` per mapper (NaN when the terrain has none)."""
    out = {}
    reference = reference_of(data, truth)  # the cloud and truth prepared once
    for mapper, (table, runs) in sweeps.items():
        found = measure(data, mapper, runs[rule_pick(table)].params.as_dict(), truth=truth,
                        reference=reference)
        by_class = found.metrics.truth.completeness_by_class if found.metrics.truth else {}
        out[mapper] = float(by_class.get(cls, np.nan))
    return out
