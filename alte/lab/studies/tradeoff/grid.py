"""The report's trade-off grid: a sweep spec run once, as trade-off tables and ablations.

:func:`run_grid` runs a sweep spec (:mod:`alte.lab.studies.sweep`: every mapper's settings on
every terrain and seed, registration cached once per terrain and seed, serial or on Dask)
and returns a :class:`Grid`: the base grid as a trade-off table (one row per terrain,
mapper, setting and seed; :data:`TRADEOFF_COLUMNS` first; with the spec's ``obstacles``
on, each map's obstacle identification, :mod:`alte.lab.studies.obstacles`) and every
ablation variant's rows. :func:`ablations` judges every claim once per variant, on the
variants' terrains, beside the base grid on the same terrains and two evaluation-only
changes (map size counted as occupied cells, so neither Octomap's free leaves nor
3D-ALTE's empty ones count; and only the thesis' own six settings per mapper, tables
5.7-5.9 and 5.12, so the thesis' selection rule and the fronts see the grid the thesis
had).
:func:`write_grid` writes ``tradeoff.csv``, ``tradeoff_variants.csv``, ``obstacles.csv``,
``obstacle_objects.csv``, ``ablation.csv`` and ``ablation_cells.csv``.
"""

from __future__ import annotations

import os
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import cast

import numpy as np
import pandas as pd

from alte.errors import ParameterError
from alte.lab.studies.analysis.evidence import EvidenceSettings, cells_table, evaluate_all
from alte.lab.studies.analysis.evidence_tables import EQUAL_SIZE, SIZES, ablation_verdicts
from alte.lab.studies.analysis.tables import write_csv
from alte.lab.studies.analysis.tradeoff import equal_size, matching, prepare
from alte.lab.studies.obstacles import OBJECTS_COLUMN, write_obstacle_tables
from alte.lab.studies.sweep import (
    BASE,
    SweepResult,
    SweepSpec,
    load_spec,
    override,
    run_sweep,
    variant_table,
)
from alte.lab.studies.thesis.claims import CLAIMS, Claim
from alte.lab.studies.thesis.numbers import CASE_MAPPERS, SWEEPS, TERRAIN_CASE

__all__ = ["OCCUPIED_SIZE", "THESIS_ROWS", "TRADEOFF_COLUMNS", "Grid", "GridTables", "ablations",
           "front_order", "grid_of", "run_grid",
           "thesis_rows", "tradeoff_table", "write_grid"]

#: The columns tradeoff.csv starts with (then the parameters as ``p_*`` and the rest).
TRADEOFF_COLUMNS = ("terrain", "case", "mapper", "params", "seed", "basis_functions",
                    "occupied_cells", "memory_bytes", "elapsed_s", "elapsed_spread", "map_cpu_s",
                    "map_cpu_spread", "time_repeats", "cost", "cost_unit", "mhd_m", "mh_ab_m",
                    "mh_ba_m", "hd_m", "hd_minus_mhd_m", "accuracy_mean_m", "completeness",
                    "height_rmse_m", "frames", "points")
#: Name of the evaluation-only ablation that counts map size as occupied cells.
OCCUPIED_SIZE = "size_occupied"
#: Name of the evaluation-only ablation that keeps only the thesis' own settings.
THESIS_ROWS = "thesis_rows"
_DROP = ("run_id", "params_json", "frames_requested", "wall_s", "cpu_s")


@dataclass(frozen=True)
class Grid:
    """A finished grid: base trade-off table, every variant's rows, and how it ran
    (``seconds``: this call's wall time; ``cpu_s``: CPU seconds of all its runs, reused
    ones included, i.e. what the grid costs on idle cores)."""

    spec: SweepSpec
    table: pd.DataFrame
    variants: pd.DataFrame
    runs: int
    ran: int
    seconds: float
    failed: list[str] = field(default_factory=list)
    cpu_s: float = float("nan")

    @property
    def variant_texts(self) -> dict[str, str]:
        """What each variant of :func:`ablations` changes, in words (base first)."""
        return {BASE: "the grid as specified, on the variants' terrains",
                OCCUPIED_SIZE: "map size counted as occupied cells (no free or empty leaves)",
                THESIS_ROWS: "only the thesis' six settings per mapper (tables 5.7-5.9, 5.12)",
                **{v.name: v.text or v.name for v in self.spec.variants}}


def tradeoff_table(rows: pd.DataFrame) -> pd.DataFrame:
    """Sweep rows (:func:`alte.lab.studies.sweep.load_results`) as a trade-off table:
    ``params`` as JSON, the terrain's ``case``, :data:`TRADEOFF_COLUMNS` first."""
    if rows.empty:
        raise ParameterError("trade-off grid: no finished runs to tabulate")
    # An imported terrain's case is its maps' (the mappers the thesis applies to it).
    by_mapper = {m: case for case, pair in CASE_MAPPERS.items() for m in pair}
    case = rows["terrain"].map(TERRAIN_CASE).fillna(rows["mapper"].map(by_mapper))
    out = rows.assign(params=rows["params_json"], case=case)
    out = out.drop(columns=[c for c in _DROP if c in out])
    first = [c for c in ("variant", *TRADEOFF_COLUMNS) if c in out]
    params = sorted(c for c in out.columns if str(c).startswith("p_"))
    rest = [c for c in out.columns if c not in first and c not in params]
    return out[first + params + rest].reset_index(drop=True)


def run_grid(spec_path: str | os.PathLike[str], *, scheduler: str = "local", workers: int = 2,
             frames: int | str | None = "spec", seeds: Sequence[int] | None = None,
             data_dir: str | None = None, output: str | os.PathLike[str] | None = None,
             plugins: bool = False, progress: bool = True) -> Grid:
    """Run the sweep spec at ``spec_path`` (``frames``/``seeds``/``data_dir`` override the
    spec's; ``frames="spec"`` keeps its own; ``plugins``: add every installed plugin
    mapper with its settings grid) into ``output`` and tabulate it."""
    spec = load_spec(spec_path)
    changes: dict[str, object] = {"data_dir": data_dir, "seeds": list(seeds) if seeds else None,
                                  "plugins": plugins}
    if frames != "spec":
        changes["frames"] = frames
    spec = override(spec, **changes)
    start = time.perf_counter()
    result = run_sweep(spec, scheduler=scheduler, workers=workers,
                       output=Path(output) if output is not None else None, progress=progress)
    return grid_of(spec, result, time.perf_counter() - start)


def grid_of(spec: SweepSpec, result: SweepResult, seconds: float) -> Grid:
    """The :class:`Grid` of a finished :func:`~alte.lab.studies.sweep.run_sweep` of ``spec``
    that took ``seconds``."""
    failed = [f"{r.terrain} seed {r.seed} {r.mapper} {dict(r.params)}: {msg}"
              for r, msg in result.failed]
    variants = tradeoff_table(variant_table(spec, result.table))
    base = variants[variants["variant"] == BASE].drop(columns="variant")
    cpu = (result.table["cpu_s"].astype(float).sum(min_count=len(result.table))  # all or NaN
           if "cpu_s" in result.table else np.nan)
    return Grid(spec, base.reset_index(drop=True), variants, len(result.table), result.ran,
                seconds, failed, float(cpu))


def thesis_rows(table: pd.DataFrame) -> pd.DataFrame:
    """The rows of ``table`` (with ``p_*`` columns) at one of the thesis' six settings of
    their mapper (tables 5.7-5.9 and 5.12)."""
    keep = pd.Series(False, index=table.index)
    for spec in SWEEPS.values():
        mine = table["mapper"] == spec["mapper"]
        for params, *_ in spec["rows"]:
            keep |= mine & matching(table, params)
    return table[keep]


def ablations(grid: Grid, claims: Sequence[Claim] = CLAIMS,
              options: EvidenceSettings | None = None) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Every claim's verdict under each variant, on the variants' terrains: (one row per
    claim with a verdict column per variant and ``moves``; every measured cell with a
    ``variant`` column). The first column, ``base``, is the base grid on those terrains."""
    options = options or EvidenceSettings()
    rows = grid.variants
    places = sorted(set(rows.loc[rows["variant"] != BASE, "terrain"]))
    if not places:
        raise ParameterError("trade-off grid: the spec has no ablation variants")
    here = rows[rows["terrain"].isin(places)]
    base = here[here["variant"] == BASE]
    tables = {BASE: (base, options),
              OCCUPIED_SIZE: (base, options.replace(size="occupied_cells"))}
    tables[THESIS_ROWS] = (thesis_rows(prepare(base)), options)
    tables |= {v.name: (here[here["variant"] == v.name], options) for v in grid.spec.variants}
    findings = {name: evaluate_all(claims, table, opts, rows)
                for name, (table, opts) in tables.items()}
    cells = [cells_table(found).assign(variant=name) for name, found in findings.items()]
    return ablation_verdicts(claims, findings), pd.concat(cells, ignore_index=True)


@dataclass(frozen=True)
class GridTables:
    """What :func:`write_grid` wrote: the CSVs, and the ablation tables (empty without
    variants)."""

    paths: list[Path]
    ablation: pd.DataFrame
    ablation_cells: pd.DataFrame


def write_grid(grid: Grid, tables_dir: str | os.PathLike[str], *,
               claims: Sequence[Claim] = CLAIMS, overwrite: bool = True) -> GridTables:
    """Write tradeoff.csv, tradeoff_variants.csv, with obstacles scored obstacles.csv and
    obstacle_objects.csv (:mod:`alte.lab.studies.obstacles`; the per-obstacle JSON stays out
    of the trade-off tables) and, with variants, ablation.csv and ablation_cells.csv into
    ``tables_dir``."""
    paths = [write_csv(frame.drop(columns=[OBJECTS_COLUMN], errors="ignore"), tables_dir,
                       name, overwrite)
             for frame, name in ((grid.table, "tradeoff"), (grid.variants, "tradeoff_variants"))]
    paths += write_obstacle_tables(grid.table, tables_dir, overwrite=overwrite)
    verdicts = cells = pd.DataFrame()
    if grid.spec.variants:
        verdicts, cells = ablations(grid, claims)
        paths += [write_csv(verdicts, tables_dir, "ablation", overwrite),
                  write_csv(cells, tables_dir, "ablation_cells", overwrite)]
    return GridTables(paths, verdicts, cells)


def _means_at_size(table: pd.DataFrame, pair: tuple[str, str], metric: str,
                   higher: bool, sizes: Sequence[float]) -> pd.DataFrame | None:
    """Mean over seeds of each mapper's ``metric`` read at ``sizes`` (terrain, level rows)."""
    if metric not in table or table[metric].isna().all() or set(pair) - set(table["mapper"]):
        return None
    reads = equal_size(table, pair, metric, levels=sizes, higher_is_better=higher)
    return reads.groupby(["terrain", "level", "mapper"])["value"].mean().unstack("mapper")


def _lead(first: float, second: float, higher: bool, names: tuple[str, str]) -> str:
    if not (pd.notna(first) and pd.notna(second)) or first == second:
        return ""
    return names[0] if (first > second) == higher else names[1]


def front_order(short: pd.DataFrame, whole: pd.DataFrame, *,
                sizes: Sequence[float] = SIZES) -> pd.DataFrame:
    """Which mapper of each pair the thesis compares leads at equal size (the fidelity
    metrics of :data:`~alte.lab.studies.analysis.evidence_tables.EQUAL_SIZE`, means over seeds), in
    two
    trade-off tables (e.g. short and whole missions), on the terrains and sizes both
    reach: one row per (terrain, metric, size) with both reads and ``same`` order."""
    rows = []
    for case, pair in CASE_MAPPERS.items():
        parts = [prepare(t[t["terrain"].map(TERRAIN_CASE) == case]) for t in (short, whole)]
        for metric, higher in EQUAL_SIZE:
            means = [_means_at_size(p, pair, metric, higher, sizes) for p in parts]
            if means[0] is None or means[1] is None:
                continue
            both = means[0].add_suffix("_short").join(means[1].add_suffix("_whole"), how="inner")
            for key, r in both.iterrows():
                # Row keys of the (terrain, level) index are tuples; pandas-stubs say Hashable.
                terrain_key, level_key = cast("tuple[str, float]", key)
                terrain, level = str(terrain_key), float(level_key)
                lead = [_lead(r[f"{pair[0]}_{k}"], r[f"{pair[1]}_{k}"], higher, pair)
                        for k in ("short", "whole")]
                if all(lead):
                    rows.append({"terrain": terrain, "metric": metric, "level": level,
                                 **{f"{m}_{k}": r[f"{m}_{k}"] for k in ("short", "whole")
                                    for m in pair},
                                 "lead_short": lead[0], "lead_whole": lead[1],
                                 "same": lead[0] == lead[1]})
    return pd.DataFrame(rows)
