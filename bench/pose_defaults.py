"""Cross-validation of the pose defaults on the two real sequences (balm_seq, balm_seq2).

Every setting of :data:`alte.studies.pose_defaults.CANDIDATES` is run with each of its
values on both sequences (``../shared/realdata``, their reference poses as the truth),
then chosen on one and scored on the other, both ways (:func:`choices`). Registrations
are cached under ``--data`` (a rerun only scores). Usage:

    python bench/pose_defaults.py [--data DIR] [--only kiss:window,refine:min_gain]
                                  [--out reports/tables]

Writes ``pose_defaults_runs.csv`` (every run) and ``pose_defaults.csv`` (the choices)
into ``--out`` and prints the choices. About 25 min of CPU for every setting.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import pandas as pd

from alte.paths import realdata_dir
from alte.studies.pose_defaults import CANDIDATES, choices, cross_validation

SEQUENCES = ("balm_seq", "balm_seq2")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", type=Path, default=Path("data"))
    parser.add_argument("--only", default="", help="SOURCE:KEY settings, comma separated")
    parser.add_argument("--out", type=Path, default=Path("reports/tables"))
    args = parser.parse_args()
    wanted = {s for s in args.only.split(",") if s}
    candidates = [c for c in CANDIDATES if not wanted or f"{c.source}:{c.key}" in wanted]
    bags = [realdata_dir() / name / "bag" for name in SEQUENCES]
    missing = [str(b) for b in bags if not b.exists()]
    if missing:
        raise SystemExit(f"absent: {', '.join(missing)}")
    runs = cross_validation(bags, candidates, data_dir=args.data, progress=True)
    table = choices(runs, candidates)
    args.out.mkdir(parents=True, exist_ok=True)
    runs.to_csv(args.out / "pose_defaults_runs.csv", index=False)
    table.to_csv(args.out / "pose_defaults.csv", index=False)
    with pd.option_context("display.width", 250, "display.max_columns", 30):
        print(runs.to_string(index=False, float_format=lambda v: f"{v:.4g}"))
        print(table.to_string(index=False, float_format=lambda v: f"{v:.4g}"))


if __name__ == "__main__":
    main()
