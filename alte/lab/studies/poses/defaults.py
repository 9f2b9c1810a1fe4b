"""Cross-validation of the pose defaults on real sequences: choose on one, score on another.

A default tuned on one recording is a guess about the next. Every setting of
:data:`CANDIDATES` is run with each of its values on every sequence through the pose
benchmark (:func:`alte.lab.studies.poses.benchmark.pose_benchmark`, the sequence's own reference
poses as the truth), and :func:`choices` then picks, on each sequence, the value that
wins there and looks it up on each other sequence, beside that one's own winner and the
current default.

The winner on a sequence has the lowest ``cloud_median_m`` (the registered cloud's
median distance to the cloud registered with the reference poses, as the pipeline
placed it); values within :data:`TIE` of it are ties, settled by the candidate's
``prefer``: the cheapest (CPU per scan) for odometry settings, the loosest threshold
for refinement (the one that still corrects the most: on a sequence whose reference
poses are exact, every correction costs, so the strictest always wins). A default
*holds* when the value chosen on each sequence scores within :data:`TOLERANCE` of the
other's best; a setting whose winners do not hold is not a default, and the safe value
(the one whose worst score over the sequences is lowest) is reported instead.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from alte.lab.studies.experiments import CACHE_DIR
from alte.lab.studies.poses.benchmark import bench_input, pose_benchmark

__all__ = ["CANDIDATES", "TIE", "TOLERANCE", "Candidate", "choices", "cross_validation"]

#: Scores within this share of a sequence's best are ties.
TIE = 0.01
#: A value chosen on one sequence holds on another when it scores within this share of
#: that sequence's best.
TOLERANCE = 0.05


@dataclass(frozen=True)
class Candidate:
    """A setting to cross-validate: the pose source it belongs to (``kiss``, ``refine``;
    ``source`` for the choice of backend itself), its key, the values tried, the
    default and how ties are settled (``cpu``: the cheapest; ``loose``: the smallest
    threshold)."""

    source: str
    key: str
    values: tuple[object, ...]
    default: object
    prefer: str = "cpu"


#: What the real sequences can test (docs/results/poses.md, "Cross-validation"): the
#: backend, KISS-ICP's map and the window, the refinement's two evidence thresholds.
#: ``deskew`` is not among them: neither real sequence carries per-point time, so it
#: changes nothing there (a setting real data cannot choose stays as it is).
CANDIDATES: tuple[Candidate, ...] = (
    Candidate("source", "backend", ("kiss", "plane"), "kiss"),
    Candidate("kiss", "window", (0, 10, 20), 20),
    Candidate("kiss", "voxel", (1.0, 1.5, 2.0), 1.5),
    Candidate("kiss", "max_points_per_voxel", (10, 20), 10),
    Candidate("kiss", "window_voxel", (0.5, 1.0), 1.0),
    Candidate("refine", "min_gain", (0.1, 0.2, 0.3, 0.4), 0.3, "loose"),
    Candidate("refine", "min_information", (0.0, 0.1), 0.0, "loose"),
)


def _row(table: pd.DataFrame, source: str) -> dict[str, object]:
    row = table.set_index("source").loc[source]
    return {k: row[k] for k in ("frames", "ate_m", "rpe_trans_pct", "cloud_median_m",
                                "cloud_aligned_median_m", "cpu_ms_per_scan", "corrected")}


def cross_validation(sequences: Sequence[str | os.PathLike[str]],
                     candidates: Sequence[Candidate] = CANDIDATES, *,
                     data_dir: str | os.PathLike[str] = "data",
                     progress: bool = False) -> pd.DataFrame:
    """One row per sequence, setting and value: the benchmark's scores of that pose source
    with that value (the other settings at their defaults), and for refinement the
    recorded poses' ``cloud_median_m`` beside it (``recorded_m``)."""
    cache = Path(data_dir) / CACHE_DIR
    rows = []
    for path in sequences:
        item = bench_input(path, data_dir=data_dir)
        name = item.name
        recorded = _row(pose_benchmark(item, ["recorded"], cache=cache), "recorded")
        for cand in candidates:
            for value in cand.values:
                source = str(value) if cand.source == "source" else cand.source
                settings = {} if cand.source == "source" else {source: {cand.key: value}}
                table = pose_benchmark(item, [source], settings=settings, cache=cache,
                                       progress=progress)
                rows.append({"sequence": name, "setting": f"{cand.source}:{cand.key}",
                             "value": value, "default": value == cand.default,
                             **_row(table, source),
                             "recorded_m": recorded["cloud_median_m"]})
    return pd.DataFrame(rows)


def _winner(scores: pd.DataFrame, prefer: str) -> object:
    """The value with the lowest ``cloud_median_m``, ties settled by ``prefer``."""
    best = float(scores["cloud_median_m"].min())
    tied = scores[scores["cloud_median_m"] <= best * (1 + TIE)]
    key = "cpu_ms_per_scan" if prefer == "cpu" else "value"
    return tied.sort_values(key, kind="stable").iloc[0]["value"]


def choices(table: pd.DataFrame, candidates: Sequence[Candidate] = CANDIDATES,
            ) -> pd.DataFrame:
    """For each setting and ordered pair of sequences (chosen on, scored on): the value
    chosen, its score on the other sequence against that one's best (``regret``: share
    above it), whether it ``holds`` (within :data:`TOLERANCE`), the default's regret
    there, and the safe value (lowest worst score over the sequences)."""
    out = []
    for cand in candidates:
        rows = table[table["setting"] == f"{cand.source}:{cand.key}"]
        if rows.empty:
            continue
        score: dict[tuple[object, str], float] = {
            (r.value, str(r.sequence)): float(r.cloud_median_m)  # type: ignore[arg-type]
            for r in rows.itertuples()}
        names = [str(n) for n in dict.fromkeys(rows["sequence"])]
        values: list[object] = list(dict.fromkeys(rows["value"]))
        safe = min(values, key=lambda v: max(score[v, n] for n in names))
        for on in names:
            chosen = _winner(rows[rows["sequence"] == on], cand.prefer)
            for other in (n for n in names if n != on):
                best = min(values, key=lambda v: score[v, other])
                out.append({"setting": f"{cand.source}:{cand.key}", "chosen_on": on,
                            "scored_on": other, "chosen": chosen,
                            "score_m": score[chosen, other], "best": best,
                            "best_m": score[best, other],
                            "regret": score[chosen, other] / score[best, other] - 1,
                            "default": cand.default,
                            "default_regret": score[cand.default, other] / score[best, other] - 1,
                            "safe": safe})
    made = pd.DataFrame(out)
    if not made.empty:
        made["holds"] = made["regret"] <= TOLERANCE
    return made
