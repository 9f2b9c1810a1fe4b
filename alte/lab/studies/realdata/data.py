"""Locate and load the real recordings, run the chapter-6 experiments, tabulate them.

:func:`locate` finds the folder (``<repo>/../shared/realdata`` unless given); when it
is absent the returned :class:`RealData` says why and every function here takes that
in its stride (empty runs, empty tables, None datasets), so the notebook runs
through and records ``{"skipped": reason}``. Reference ground labels of the ISPRS
samples are membership in the ``*-ground.pcd`` subset (same offset, KD-tree match
within 1e-3 m); float32 storage makes a few points coincide, so a point sharing a
ground point's coordinates counts as ground (samp11: 21,793 points match its 21,786
ground points).
"""

from __future__ import annotations

import os
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from alte.errors import ParameterError
from alte.ground.filters import MIN_POINTS, filter_ground
from alte.ground.settings import GroundSettings, ground_settings
from alte.io.points.pointfiles import local_origin, read_points
from alte.lab.studies.analysis.tables import write_csv as write_tables_csv
from alte.lab.studies.experiments import Measured, measure
from alte.lab.studies.realdata.ground import ground_errors, map_heights, reference_labels
from alte.paths import realdata_dir
from alte.pipeline import (
    DomainPolicy,
    FrameSettings,
    MapSettings,
    PoseSource,
    Registered,
    open_input,
    prepare,
)
from alte.progress import bar as progress_bar

__all__ = [
    "BASELINE",
    "ISPRS_FOLDER",
    "GroundRun",
    "IsprsSample",
    "RealData",
    "dataset_summary",
    "default_dir",
    "ground_runs",
    "ground_table",
    "isprs_sample",
    "isprs_samples",
    "locate",
    "map_runs",
    "map_table",
    "results",
    "scan_dataset",
    "vlp16_dataset",
    "write_csv",
]

#: The folder of the ISPRS filter-test samples: ``<name>-utm.pcd`` with its reference
#: bare earth ``<name>-utm-ground.pcd`` (today samp11, samp21, samp31 of the fifteen).
ISPRS_FOLDER = "isprs_terrain"
#: Name of the map-free side (the filter on raw point heights) in the ground runs and table.
BASELINE = "points"


@dataclass(frozen=True)
class RealData:
    """The real-data folder, or ``root=None`` and the ``reason`` it is unusable."""

    root: Path | None
    reason: str = ""

    @property
    def available(self) -> bool:
        """True when the folder exists."""
        return self.root is not None

    def file(self, *parts: str) -> Path:
        """A path inside the folder (readers name it when it is missing)."""
        if self.root is None:
            raise ParameterError(f"real data unavailable: {self.reason}")
        return self.root.joinpath(*parts)

    def describe(self) -> str:
        """One line for the notebook: where the data are, or why the chapter is skipped."""
        return f"real data: {self.root}" if self.root else f"SKIPPED: {self.reason}"


def default_dir() -> Path:
    """``<repo>/../shared/realdata`` (:func:`alte.paths.realdata_dir`)."""
    return realdata_dir()


def locate(path: str | os.PathLike[str] | None = None) -> RealData:
    """The real-data folder ``path`` (empty/None: :func:`default_dir`), or why it is absent."""
    folder = default_dir() if path is None or str(path) == "" else Path(path)
    if not folder.is_dir():
        return RealData(None, f"real-data folder {folder} is absent; chapter 6 is skipped "
                              "(see ../shared/realdata/SOURCES.md for the recordings)")
    return RealData(folder.resolve())


# ---------------------------------------------------------------------- data sets


@dataclass(eq=False)
class IsprsSample:
    """An ISPRS sample in local coordinates (``origin`` subtracted) and its labels."""

    name: str
    points: NDArray[np.float64]
    reference: NDArray[np.bool_]
    origin: NDArray[np.float64]


def isprs_samples(data: RealData) -> tuple[str, ...]:
    """Every ISPRS sample present (a ``<name>-utm.pcd`` with its ``-ground`` subset), in
    name order; () when the folder is absent."""
    if not data.available or not data.file(ISPRS_FOLDER).is_dir():
        return ()
    clouds = data.file(ISPRS_FOLDER).glob("*-utm.pcd")
    return tuple(sorted(p.name.removesuffix("-utm.pcd") for p in clouds
                        if p.with_name(p.name.replace("-utm.pcd", "-utm-ground.pcd")).is_file()))


def isprs_sample(data: RealData, name: str) -> IsprsSample:
    """Read ``isprs_terrain/<name>-utm.pcd`` and label it with ``<name>-utm-ground.pcd``."""
    points = read_points(data.file(ISPRS_FOLDER, f"{name}-utm.pcd"))
    ground = read_points(data.file(ISPRS_FOLDER, f"{name}-utm-ground.pcd"))
    origin = local_origin(points)
    return IsprsSample(name, points - origin, reference_labels(points - origin, ground - origin),
                       origin)


@dataclass(eq=False)
class GroundRun:
    """One sample filtered with one surface source: the mask, the labels and the scores."""

    sample: str
    mapper_name: str
    params: dict[str, object]
    points: NDArray[np.float64]
    ground: NDArray[np.bool_]
    reference: NDArray[np.bool_]
    metrics: dict[str, float] = field(default_factory=dict)


def _map_ground(points: NDArray[np.float64], heights: NDArray[np.float64],
                method: str | None, settings: GroundSettings | None) -> NDArray[np.bool_]:
    """The filter run on the map's heights (each point at its leaf's height), then every
    raw point judged against that bare earth with the filter's own tolerance; points of
    unknown leaves are not ground."""
    known = np.isfinite(heights)
    ground = np.zeros(len(points), bool)
    if known.sum() >= MIN_POINTS:
        seen = filter_ground(np.column_stack([points[known, :2], heights[known]]), method,
                             settings)
        ground[known] = seen.classify(points[known, 2])
    return ground


def _ground_run(sample: IsprsSample, name: str, params: Mapping[str, object],
                method: str | None, settings: GroundSettings | None) -> GroundRun:
    pts, extra = sample.points, {"basis_functions": 0, "map_s": 0.0}
    if name == BASELINE:
        ground = filter_ground(pts, method, settings).ground
    else:
        spec = MapSettings(name, dict(params))
        mapper = spec.cls(None, record=spec.record)
        start = time.perf_counter()
        mapper.build(pts)
        extra = {"basis_functions": int(mapper.basis_functions),
                 "map_s": time.perf_counter() - start}
        ground = _map_ground(pts, map_heights(mapper.cells(), pts), method, settings)
    metrics = {**extra, "points": len(pts), **ground_errors(ground, sample.reference)}
    return GroundRun(sample.name, name, dict(params), pts, ground, sample.reference, metrics)


def ground_runs(data: RealData, samples: Sequence[str] | None,
                mappers: Mapping[str, Mapping[str, object]], *, method: str | None = None,
                settings: Mapping[str, object] | None = None, baseline: bool = True,
                progress: bool = True) -> list[GroundRun]:
    """Filter the named samples (None: every sample present, :func:`isprs_samples`) with
    the ground filter ``method`` and ``settings`` over its published ones (neither: the
    ground stage's default) on the raw points (the baseline) and on every 2D mapper's
    heights, the same filter on both sides; [] if the folder is absent."""
    if not data.available:
        return []
    chosen = ground_settings(method, settings)
    present = isprs_samples(data)
    samples = present if samples is None else tuple(samples)
    bad = sorted(set(samples) - set(present))
    if bad:
        raise ParameterError(f"ISPRS samples {bad} unknown; samples present in "
                             f"{data.file(ISPRS_FOLDER)}: {list(present)}")
    sources = {**({BASELINE: {}} if baseline else {}), **mappers}
    runs = []
    for name in progress_bar(samples, desc="ISPRS samples", disable=not progress):
        sample = isprs_sample(data, name)
        runs += [_ground_run(sample, m, p, method, chosen) for m, p in sources.items()]
    return runs


def ground_table(runs: Sequence[GroundRun]) -> pd.DataFrame:
    """One row per sample x surface source: map size and time, type I/II/total errors."""
    return pd.DataFrame([{"sample": r.sample, "filter": r.mapper_name,
                          "params": ", ".join(f"{k}={v}" for k, v in r.params.items()),
                          **r.metrics} for r in runs])


def scan_dataset(data: RealData) -> Registered | None:
    """``octomap_scan/scan.dat.bz2``: one scan, sensor at the origin (None when absent)."""
    if not data.available:
        return None
    return prepare(open_input(data.file("octomap_scan", "scan.dat.bz2")))


def vlp16_dataset(data: RealData, voxel: float | None = None,
                  frames: int | None = None) -> Registered | None:
    """The VLP-16 packet bag decoded and registered with the identity pose (stationary
    sensor, no pose topic, identity mount); ``voxel`` grid-averages each frame and
    ``frames`` keeps at most that many rotations, evenly spaced (None: all)."""
    if not data.available:
        return None
    spec = FrameSettings(frames=frames, voxel=voxel, poses=PoseSource.IDENTITY)
    return prepare(open_input(data.file("vlp16_packets", "bag")), spec)


def map_runs(dataset: Registered | None, mappers: Mapping[str, Mapping[str, object]],
             progress: bool = True) -> list[Measured]:
    """Map ``dataset`` with each mapper over the cube of its points (timed, measured);
    [] when None."""
    if dataset is None:
        return []
    name = dataset.source.name
    return [measure(dataset, m, spec=MapSettings(m, dict(p), domain=DomainPolicy.DATA))
            for m, p in progress_bar(mappers.items(), desc=name, disable=not progress)]


def map_table(runs: Sequence[Measured]) -> pd.DataFrame:
    """Basis functions, occupied cells, time, memory, HD/MHD (cloud vs corners) per map."""
    keys = ("elapsed_s", "basis_functions", "occupied_cells", "memory_bytes", "hd_m", "mhd_m")
    return pd.DataFrame([{"mapper": r.name,
                          "params": ", ".join(f"{k}={v}" for k, v in r.params.as_dict().items()),
                          **{k: getattr(r.metrics, k) for k in keys}} for r in runs])


def dataset_summary(dataset: Registered) -> dict[str, str | int]:
    """Name, frames, registered points and raw points read of a real-data input."""
    return {"name": dataset.source.name, "frames": len(dataset), "points": len(dataset.cloud),
            "raw_points": dataset.counts.registration.points_in}


# ---------------------------------------------------------------------- output


def write_csv(table: pd.DataFrame, out_dir: str | os.PathLike[str], name: str) -> Path | None:
    """Write ``out_dir/name.csv`` atomically (replaces it); nothing for an empty table."""
    return None if table.empty else write_tables_csv(table, out_dir, name, overwrite=True)


def results(data: RealData, **parts: object) -> dict[str, object]:
    """The notebook's results (tables as rows, datasets as tallies), or ``{"skipped":
    reason}`` alone when the data are absent."""
    if not data.available:
        return {"skipped": data.reason}
    return {"realdata_dir": str(data.root), **{k: _records(v) for k, v in parts.items()}}


def _records(value: object) -> object:
    """Tables as lists of rows, datasets as their name and tallies, the rest as is."""
    if isinstance(value, pd.DataFrame):
        return value.to_dict(orient="records")
    if isinstance(value, Registered):
        return dataset_summary(value)
    return value
