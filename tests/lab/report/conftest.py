"""Tiny fake notebooks for the report runner tests (no dependence on the real ones)."""

from __future__ import annotations

import json
from pathlib import Path

import nbformat
import pandas as pd
import pytest

from alte.lab.plot.figure import Caption, Plot

GOOD_PARAMS = ('OUT_DIR = "reports/scratch/good"\nTABLES_DIR = "reports/scratch/tables"\n'
               "SEED = 0\nROWS = 3\n")
GOOD_BODY = """\
import numpy as np
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
from pathlib import Path
from alte.fsutil import atomic_path
from alte.lab.notebook import save_figure, save_results
from alte.lab.plot.figure import Caption, Plot
rng = np.random.default_rng(SEED)
values = rng.normal(size=(ROWS, 2))
path = Path(TABLES_DIR) / "table_5_1.csv"
with atomic_path(path, overwrite=True) as tmp:
    np.savetxt(tmp, values, delimiter=",", header="a,b", comments="", fmt="%.12g")
fig, ax = plt.subplots()
ax.plot(values[:, 0])
save_figure(Plot(fig, Caption("Curve", "The first column, row by row.")), OUT_DIR, "curve")
print("rows", ROWS)
import json, os
names = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS")
(Path(OUT_DIR) / "threads.json").write_text(json.dumps({n: os.environ.get(n) for n in names}))
"""
BAD_PARAMS = 'OUT_DIR = "reports/scratch/bad"\nMESSAGE = "boom"\n'
BAD_BODY = 'print("before the failure")\nraise ValueError(MESSAGE)\n'
SLOW_PARAMS = 'OUT_DIR = "reports/scratch/slow"\nSLEEP = 0.0\n'
SLOW_BODY = """\
import os, time
from pathlib import Path
Path(OUT_DIR).mkdir(parents=True, exist_ok=True)
(Path(OUT_DIR) / "kernel.pid").write_text(str(os.getpid()))
time.sleep(SLEEP)
"""


def make_notebook(path: Path, params: str, body: str, last: str | None = None) -> Path:
    """A notebook with a ``parameters`` cell, a body and a save_results cell."""
    nb = nbformat.v4.new_notebook()
    nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3",
                                 "language": "python"}
    nb.metadata["language_info"] = {"name": "python"}
    cell = nbformat.v4.new_code_cell(params)
    cell.metadata["tags"] = ["parameters"]
    last = last or 'from alte.lab.notebook import save_results\nsave_results(OUT_DIR, {"ok": True})'
    nb.cells = [nbformat.v4.new_markdown_cell("# fake"), cell,
                nbformat.v4.new_code_cell(body), nbformat.v4.new_code_cell(last)]
    path.parent.mkdir(parents=True, exist_ok=True)
    nbformat.write(nb, str(path))
    return path


@pytest.fixture
def notebooks(tmp_path: Path) -> Path:
    """A folder with good.ipynb, bad.ipynb and slow.ipynb."""
    folder = tmp_path / "notebooks"
    make_notebook(folder / "good.ipynb", GOOD_PARAMS, GOOD_BODY)
    make_notebook(folder / "bad.ipynb", BAD_PARAMS, BAD_BODY)
    make_notebook(folder / "slow.ipynb", SLOW_PARAMS, SLOW_BODY)
    return folder


def write_plan(path: Path, entries: list[dict]) -> Path:
    """A JSON plan file for ``alte report --plan``."""
    path.write_text(json.dumps(entries))
    return path


def _png(folder: Path, name: str, caption: Caption | None = None) -> None:
    """A small real PNG (browsers must be able to decode it) saved with ``caption``
    (one in the figure's name by default)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from alte.lab.notebook import save_figure

    fig, ax = plt.subplots(figsize=(2, 1.5))
    ax.plot([0, 1], [1, 0])
    text = Caption(name.replace("_", " ").capitalize(), f"The {name} figure of {{TERRAIN}}.")
    save_figure(Plot(fig, caption or text), folder, name)
    plt.close(fig)


def make_front_run(run_dir: Path) -> dict:
    """A finished run folder as the report writes it: two notebook runs (one failed), a
    chapter 4 run with figures and results, chapter 5 with trade-off figures, the claims
    table from a synthetic trade-off table, key and other tables. Returns its record."""
    from support.tradeoff import Curve, synthetic_tradeoff

    from alte.lab.studies.analysis.evidence import claims_table, evaluate_all
    from alte.lab.studies.analysis.tables import write_csv
    from alte.lab.studies.thesis.claims import CLAIMS

    tables = run_dir / "tables"
    trade = synthetic_tradeoff({"alte2d": Curve(scale=0.5), "alte3d": Curve(scale=0.5)})
    write_csv(claims_table(evaluate_all(CLAIMS[:12], trade)), tables, "claims")
    write_csv(trade, tables, "tradeoff")
    pd.DataFrame({"mapper": ["quadtree", "alte2d"], "params": ["max_points=150", "kappa=1"],
                  "mhd_m": [0.618, 2.23], "thesis_mhd_m": [1.09, 0.85],
                  "basis_functions": [1435, 232], "thesis_basis_functions": [4399, 220],
                  "memory_bytes": [123, 456]}).to_csv(tables / "table_5_10.csv", index=False)
    pd.DataFrame({"a": [1, 2], "b_m": [0.5, 0.25]}).to_csv(tables / "extra.csv", index=False)
    pd.DataFrame({"case": ["lan", "lan"], "terrain": ["sim_lan_2"] * 2,
                  "basis_functions": [1000, 1000], "mapper": ["quadtree", "alte2d"],
                  "mhd_m": [0.61, 0.66], "ci_low_m": [0.6, 0.64], "ci_high_m": [0.62, 0.7],
                  "seeds": [3, 3]}).to_csv(tables / "key_equal_size.csv", index=False)
    pd.DataFrame({"id": [c.id for c in CLAIMS[:3]], "section": ["5.1"] * 3,
                  "claim": [c.quote for c in CLAIMS[:3]], "base": ["holds"] * 3,
                  "set_b_centers": ["holds", "does not hold", "holds"],
                  "moves": ["", "set_b_centers", ""]}).to_csv(tables / "ablation.csv",
                                                              index=False)
    from alte.lab.plot.terrain import CLOUD, SWEEPS, TERRAIN
    from alte.lab.studies.tradeoff.figures import CURVES, EQUAL_SIZE

    for name, caption in (("terrain", TERRAIN), ("cloud", CLOUD), ("mystery", None)):
        _png(run_dir / "ch4_sim_lan_1", name, caption)
    for name, caption in (("fig_5_2", SWEEPS["quadtree"]),
                          ("tradeoff_mhd", CURVES["tradeoff_mhd"].caption),
                          ("equal_size_2d", EQUAL_SIZE["2d"])):
        _png(run_dir / "ch5_analysis", name, caption)
    (run_dir / "ch4_sim_lan_1" / "results.json").write_text(json.dumps(
        {"terrain": "sim_lan_1", "frames": 40, "points": 120161, "rows": [0, 1, 2],
         "maps": {"quadtree": {"params": {"max_points": 200}}},
         "sites": [{"x": 1.0}], "table": "reports/x/tables/t.csv",
         "captions": {"mystery": "A caption the notebook wrote itself."}}))
    runs = [{"name": "ch4_sim_lan_1", "status": "ok", "seconds": 1.25,
             "notebook": "ch4_sim_lan_1.ipynb", "html": "ch4_sim_lan_1.html", "error": None,
             "parameters": {"TERRAIN": "sim_lan_1", "FRAMES": 40}},
            {"name": "ch5_analysis", "status": "failed", "seconds": 0.5,
             "notebook": "ch5_analysis.failed.ipynb", "html": "ch5_analysis.failed.html",
             "error": "cell 2: ValueError: <boom>", "parameters": {}}]
    for run in runs:
        (run_dir / run["html"]).write_text("<!DOCTYPE html><title>nb</title>")
        (run_dir / run["notebook"]).write_text("{}")
    return {"mode": "quick", "started": "2024-01-01T00:00:00+00:00", "seconds": 2.0,
            "runs": runs, "problems": ["terrain exp_lan_2: no data"]}
