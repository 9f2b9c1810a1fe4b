"""The committed real-terrain evidence: made once by one command, read by the report.

``python -m alte.lab.studies.realterrain [FOLDER]`` runs :func:`~alte.lab.studies.realterrain.
evidence.evidence_rows` on every shared site (``../shared/realdata``) and writes
``FOLDER/realterrain_fronts.csv`` with ``provenance.json`` (the command, commit, sites
and their tiles, seeds, scans, CPU and wall seconds, the machine). The default folder is
:data:`EVIDENCE` (committed); ``make report`` reads it (:func:`load_evidence`) and
copies the table into the run's tables, never recomputing it.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import time
from datetime import UTC, datetime
from pathlib import Path

import pandas as pd

from alte.lab.studies.analysis.tables import write_csv
from alte.lab.studies.missions import git_commit
from alte.lab.studies.realterrain.evidence import COLUMNS, GRID, Mappers, evidence_rows
from alte.lab.studies.realterrain.sites import SITES
from alte.paths import realdata_dir, resolve

__all__ = ["EVIDENCE", "TABLE", "load_evidence", "main", "summary", "write_evidence"]

#: Where the evidence is committed (relative to the repository root).
EVIDENCE = Path("notebooks/realterrain")
#: The table's name (CSV stem), in the evidence folder and in a report's tables.
TABLE = "realterrain_fronts"


def write_evidence(folder: str | os.PathLike[str] = EVIDENCE, *,
                   seeds: tuple[int, ...] = (0, 1), frames: int = 20,
                   data_dir: str | os.PathLike[str] = "data/real", command: str = "",
                   only: list[str] | None = None, mappers: Mappers | None = None) -> Path:
    """Run the evidence on every site present (or those named ``only``) and write the
    folder (module docstring); each site's rows are kept in ``FOLDER/sites/`` as it
    finishes, so a rerun does only the sites missing (delete them to redo)."""
    where = resolve(folder)
    root = realdata_dir()
    start, cpu, began = time.perf_counter(), time.process_time(), datetime.now(UTC)
    parts = where / "sites"
    for site in [s for s in SITES if s.name in (only or [s.name for s in SITES])]:
        done = parts / f"{site.name}.csv"  # each site kept as it finishes: a rerun resumes
        if not done.is_file():
            rows = evidence_rows(root, resolve(data_dir), sites=(site,), seeds=seeds,
                                 frames=frames, progress=False, mappers=mappers)
            write_csv(rows, parts, site.name, overwrite=True)
    table = pd.concat([pd.read_csv(p) for p in sorted(parts.glob("*.csv"))],
                      ignore_index=True)
    path = write_csv(table, where, TABLE, overwrite=True)
    provenance = {
        "command": command or "python -m alte.lab.studies.realterrain", "commit": git_commit(),
        "sites": [{"name": s.name, "tiles": list(s.tiles), "region": s.region,
                   "crs": s.crs, "ground": s.ground, "note": s.note} for s in SITES],
        "seeds": list(seeds), "frames": frames, "grid": GRID, "rows": len(table),
        "cpu_s": round(time.process_time() - cpu, 1),
        "wall_s": round(time.perf_counter() - start, 1), "started": began.isoformat(),
        "finished": datetime.now(UTC).isoformat(),
        "machine": {"platform": platform.platform(), "cpus": os.cpu_count()}}
    (where / "provenance.json").write_text(json.dumps(provenance, indent=2) + "\n")
    return path


def load_evidence(folder: str | os.PathLike[str] = EVIDENCE) -> pd.DataFrame:
    """The committed table (empty when absent)."""
    path = resolve(folder) / f"{TABLE}.csv"
    return pd.read_csv(path) if path.is_file() else pd.DataFrame(columns=list(COLUMNS))


def summary(table: pd.DataFrame) -> pd.DataFrame:
    """Per terrain, evidence and mapper: its class, the mapper's best truth (mean over
    seeds of a setting; landing: height RMSE, navigation: mean accuracy among settings
    covering at least half the surface) and that setting's size and completeness."""
    if table.empty:
        return pd.DataFrame()
    rows = []
    keys = ["terrain", "terrain_class", "evidence", "case", "mapper"]
    for key, part in table.groupby(keys, sort=True):
        metric = "height_rmse_m" if key[3] == "lan" else "accuracy_mean_m"
        means = part.groupby("params")[[metric, "completeness", "basis_functions"]].mean()
        fit = means if key[3] == "lan" else means[means["completeness"] >= 0.5]
        fit = fit.dropna(subset=[metric])
        if fit.empty:
            continue
        best = fit.sort_values(metric).iloc[0]
        rows.append({**dict(zip(keys, key, strict=True)), "metric": metric,
                     "best": best[metric], "completeness": best["completeness"],
                     "basis_functions": best["basis_functions"],
                     "seeds": int(part["seed"].nunique())})
    return pd.DataFrame(rows)


def main(argv: list[str] | None = None) -> int:
    """``python -m alte.lab.studies.realterrain [FOLDER] [--seeds 0,1] [--frames 20] [--sites
    A,B]``."""
    p = argparse.ArgumentParser(prog="python -m alte.lab.studies.realterrain",
                                description=__doc__)
    p.add_argument("folder", nargs="?", default=str(EVIDENCE))
    p.add_argument("--seeds", default="0,1")
    p.add_argument("--sites", default=None, help="comma-separated site names (default: all)")
    p.add_argument("--frames", type=int, default=20)
    p.add_argument("--data", default="data/real", help="where the flown terrains go")
    p.add_argument("--plugins", action="store_true",
                   help="also map the installed plugin mappers (their settings grids)")
    p.add_argument("--mappers", default=None,
                   help="comma-separated mapper names: only these (e.g. a plugin's rows)")
    args = p.parse_args(argv)
    seeds = tuple(int(s) for s in args.seeds.split(","))
    only = args.sites.split(",") if args.sites else None
    path = write_evidence(args.folder, seeds=seeds, frames=args.frames, data_dir=args.data,
                          only=only, mappers=Mappers(args.plugins, tuple(
                              args.mappers.split(",")) if args.mappers else ()),
                          command=" ".join(["python -m alte.lab.studies.realterrain",
                                            *(argv if argv is not None else sys.argv[1:])]))
    print(f"wrote {path}")
    return 0
