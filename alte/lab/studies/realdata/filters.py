"""The ground filters scored on real terrain: how the ground stage's default was chosen.

Two data sets with reference ground, from ``../shared/realdata``:

* ``isprs``: the ISPRS filter-test samples (Sithole & Vosselman 2004), the reference
  bare earth of each (:func:`~alte.lab.studies.realdata.data.isprs_sample`);
* ``als``: the ALS and drone tiles in ``als/``, their producers' class 2 as the
  reference (noise classes 7 and 18 left out). Those classes are the producers' own
  and incomplete: many class-1 points lie on the ground (:func:`reference_gaps`), so
  the agreement there is with a survey's classification, not with the truth.

:func:`filter_table` runs every candidate (:data:`CANDIDATES`) on every cloud and
scores it (type I, type II, total error, Cohen's kappa, CPU seconds);
:func:`mean_table` averages per data set. The default is chosen on one data set and
checked on the other (:func:`choose`). :data:`PUBLISHED` holds the papers' own figures
on the 15 ISPRS samples, to read beside ours.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd
from numpy.typing import NDArray
from scipy.interpolate import LinearNDInterpolator

from alte.errors import ParameterError
from alte.ground.filters import filter_ground
from alte.ground.settings import DEFAULT_METHOD, DEFAULT_SETTINGS, GroundSettings, ground_settings
from alte.lab.studies.realdata.data import RealData, isprs_sample, isprs_samples
from alte.lab.studies.realdata.ground import ground_errors
from alte.progress import bar as progress_bar

__all__ = ["ALS_FOLDER", "CANDIDATES", "NOISE_CLASSES", "PUBLISHED", "LabelledCloud",
           "als_tile", "als_tiles", "choose", "filter_table", "labelled_clouds", "mean_table",
           "reference_gaps"]

#: Folder of the ALS / drone tiles with a producer's ground class.
ALS_FOLDER = "als"
#: ASPRS noise classes (low point, high noise): left out of the scores.
NOISE_CLASSES = (7, 18)

#: Candidate name -> (method, settings): each method with its published defaults, and
#: the ground stage's default.
CANDIDATES: dict[str, tuple[str, GroundSettings]] = {
    "default": (DEFAULT_METHOD, DEFAULT_SETTINGS),
    "smrf published": ("smrf", ground_settings("smrf")),
    "csf published": ("csf", ground_settings("csf")),
    "morph": ("morph", ground_settings("morph")),
    "plane": ("plane", ground_settings("plane")),
}

#: The papers' own figures on the 15 ISPRS samples (mean per sample; NaN: not given).
PUBLISHED = pd.DataFrame([
    {"filter": "SMRF, one parameter set", "mean_total_pct": float("nan"),
     "mean_kappa_pct": 85.4, "source": "Pingel, Clarke & McBride (2013), abstract"},
    {"filter": "SMRF, tuned per sample", "mean_total_pct": float("nan"),
     "mean_kappa_pct": 90.02, "source": "Pingel, Clarke & McBride (2013), abstract"},
    {"filter": "CSF, set per sample", "mean_total_pct": 4.58,
     "mean_kappa_pct": float("nan"), "source": "Zhang et al. (2016), abstract"},
])


@dataclass(frozen=True, eq=False)
class LabelledCloud:
    """A real cloud (local coordinates) with its reference ground mask."""

    name: str
    dataset: str
    points: NDArray[np.float64]
    reference: NDArray[np.bool_]


def als_tiles(data: RealData) -> tuple[str, ...]:
    """The LAS/LAZ tiles under ``als/`` (paths relative to it), in name order."""
    if not data.available or not data.file(ALS_FOLDER).is_dir():
        return ()
    folder = data.file(ALS_FOLDER)
    return tuple(sorted(str(p.relative_to(folder)) for p in folder.rglob("*")
                        if p.suffix.lower() in (".las", ".laz")))


def als_tile(data: RealData, name: str) -> LabelledCloud:
    """An ALS tile, noise classes left out, its class 2 as the reference."""
    import laspy

    las = laspy.read(data.file(ALS_FOLDER, name))
    points = np.column_stack([np.asarray(las.x), np.asarray(las.y), np.asarray(las.z)])
    classes = np.asarray(las.classification)
    keep = ~np.isin(classes, NOISE_CLASSES)
    points = points[keep] - np.floor(points[keep].min(axis=0))
    return LabelledCloud(name, "als", points, classes[keep] == 2)


def labelled_clouds(data: RealData, isprs: Sequence[str] | None = None,
                    als: Sequence[str] | None = None) -> list[LabelledCloud]:
    """The named ISPRS samples and ALS tiles (None: all present); [] without the data."""
    if not data.available:
        return []
    out = []
    for name in isprs_samples(data) if isprs is None else isprs:
        sample = isprs_sample(data, name)
        out.append(LabelledCloud(name, "isprs", sample.points, sample.reference))
    out += [als_tile(data, name) for name in (als_tiles(data) if als is None else als)]
    return out


def _candidates(names: Sequence[str] | None) -> dict[str, tuple[str, GroundSettings]]:
    unknown = sorted(set(names or ()) - set(CANDIDATES))
    if unknown:
        raise ParameterError(f"ground filters {unknown} unknown; valid: {', '.join(CANDIDATES)}")
    return dict(CANDIDATES) if names is None else {k: CANDIDATES[k] for k in names}


def filter_table(clouds: Sequence[LabelledCloud], names: Sequence[str] | None = None, *,
                 progress: bool = True) -> pd.DataFrame:
    """One row per cloud x candidate (``names`` of :data:`CANDIDATES`; None: all): its
    errors and kappa (%), ground shares, CPU seconds."""
    rows = []
    runs = [(c, name, spec) for c in clouds for name, spec in _candidates(names).items()]
    for cloud, name, (method, settings) in progress_bar(runs, desc="ground filters", unit="run",
                                                disable=not progress):
        result = filter_ground(cloud.points, method, settings)
        scores = ground_errors(result.ground, cloud.reference)
        rows.append({"dataset": cloud.dataset, "cloud": cloud.name, "filter": name,
                     "method": method,
                     "settings": ", ".join(f"{k}={v}" for k, v in settings.as_dict().items()),
                     "points": len(cloud.points),
                     "reference_ground_pct": 100 * float(cloud.reference.mean()),
                     "ground_pct": 100 * result.share,
                     **{k: scores[k] for k in ("type_i_pct", "type_ii_pct", "total_pct",
                                               "kappa_pct")},
                     "cpu_s": result.cpu_s,
                     "points_per_cpu_s": len(cloud.points) / max(result.cpu_s, 1e-9)})
    return pd.DataFrame(rows)


def mean_table(table: pd.DataFrame) -> pd.DataFrame:
    """Mean type I, type II, total error and kappa per data set x filter (the clouds count
    alike, as the ISPRS test averages its samples)."""
    if table.empty:
        return table
    cols = ["type_i_pct", "type_ii_pct", "total_pct", "kappa_pct", "cpu_s"]
    return table.groupby(["dataset", "filter"], sort=False)[cols].mean().reset_index()


def choose(table: pd.DataFrame, on: str, check: str) -> dict[str, object]:
    """The filter with the highest mean kappa on data set ``on`` and, for it and for
    every other filter, the mean kappa on ``check``."""
    means = mean_table(table).set_index(["dataset", "filter"])["kappa_pct"]
    if on not in means.index.get_level_values(0):
        raise ParameterError(f"choose: no data set {on!r} in the table")
    best = str(means[on].idxmax())
    return {"chosen_on": on, "chosen": best, "kappa_on": float(means[on][best]),
            "checked_on": check,
            "kappa_check": {str(k): float(v) for k, v in means.get(check, pd.Series()).items()}}


def reference_gaps(cloud: LabelledCloud, tolerance: float = 0.3) -> float:
    """Share (%) of the reference's non-ground points within ``tolerance`` m of the
    surface its ground points span (a TIN): points any ground filter calls ground that
    the producer left unclassified."""
    ground = cloud.points[cloud.reference]
    other = cloud.points[~cloud.reference]
    if len(ground) < 3 or len(other) == 0:
        return float("nan")
    surface = LinearNDInterpolator(ground[:, :2], ground[:, 2])(other[:, :2])
    with np.errstate(invalid="ignore"):
        return 100.0 * float(np.mean(np.abs(other[:, 2] - surface) <= tolerance))
