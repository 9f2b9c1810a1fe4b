"""Tiny fake notebooks for the report runner tests (no dependence on the real ones)."""

from __future__ import annotations

import json
from pathlib import Path

import nbformat
import pytest

GOOD_PARAMS = ('OUT_DIR = "reports/scratch/good"\nTABLES_DIR = "reports/scratch/tables"\n'
               "SEED = 0\nROWS = 3\n")
GOOD_BODY = """\
import numpy as np
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
from pathlib import Path
from alte.fsutil import atomic_path
from alte.notebook import save_figure, save_results
rng = np.random.default_rng(SEED)
values = rng.normal(size=(ROWS, 2))
path = Path(TABLES_DIR) / "table_5_1.csv"
with atomic_path(path, overwrite=True) as tmp:
    np.savetxt(tmp, values, delimiter=",", header="a,b", comments="", fmt="%.12g")
fig, ax = plt.subplots()
ax.plot(values[:, 0])
save_figure(fig, OUT_DIR, "curve")
print("rows", ROWS)
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
    last = last or 'from alte.notebook import save_results\nsave_results(OUT_DIR, {"ok": True})'
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
