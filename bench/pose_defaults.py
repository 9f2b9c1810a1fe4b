"""Cross-validation of the pose defaults on the two real sequences (balm_seq, balm_seq2),
and table 6.4 (every pose source on both).

Every setting of :data:`alte.lab.studies.poses.defaults.CANDIDATES` is run with each of its
values on both sequences (``../shared/realdata``, their reference poses as the truth),
then chosen on one and scored on the other, both ways (:func:`choices`). Registrations
are cached under ``--data`` (a rerun only scores). Usage:

    python bench/pose_defaults.py [--data DIR] [--only kiss:window,refine:min_gain]
                                  [--table recorded,kiss,refine] [--out notebooks/poses]

Writes ``pose_defaults_runs.csv`` (every run) and ``pose_defaults.csv`` (the choices)
into ``--out`` and prints the choices; with ``--table SOURCES`` also ``table_6_4.csv``
(the pose benchmark of those sources on both sequences; ``--only none`` for the table
alone). About 40 min of CPU on one core for every setting and the table.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import pandas as pd

from alte.lab.studies.poses.benchmark import REAL_SEQUENCES, realdata_table
from alte.lab.studies.poses.defaults import CANDIDATES, choices, cross_validation
from alte.paths import realdata_dir


def _print(table: pd.DataFrame) -> None:
    with pd.option_context("display.width", 250, "display.max_columns", 30):
        print(table.to_string(index=False, float_format=lambda v: f"{v:.4g}"), flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", type=Path, default=Path("data"))
    parser.add_argument("--only", default="", help="SOURCE:KEY settings, comma separated "
                        "('none': no cross-validation)")
    parser.add_argument("--table", default="", help="pose sources of table 6.4, comma "
                        "separated (none by default)")
    parser.add_argument("--out", type=Path, default=Path("notebooks/poses"))
    args = parser.parse_args()
    wanted = {s for s in args.only.split(",") if s}
    candidates = [c for c in CANDIDATES if not wanted or f"{c.source}:{c.key}" in wanted]
    bags = [realdata_dir() / name / "bag" for name in REAL_SEQUENCES]
    missing = [str(b) for b in bags if not b.exists()]
    if missing:
        raise SystemExit(f"absent: {', '.join(missing)}")
    args.out.mkdir(parents=True, exist_ok=True)
    if candidates:
        runs = cross_validation(bags, candidates, data_dir=args.data, progress=True)
        runs.to_csv(args.out / "pose_defaults_runs.csv", index=False)
        table = choices(runs, candidates)
        table.to_csv(args.out / "pose_defaults.csv", index=False)
        _print(runs)
        _print(table)
    if args.table:
        poses = realdata_table(realdata_dir(), sources=args.table.split(","),
                               data_dir=args.data, progress=True)
        poses.to_csv(args.out / "table_6_4.csv", index=False)
        _print(poses)


if __name__ == "__main__":
    main()
