"""A 10^7-point cloud maps with every mapper within the 24 GiB, 2-core machine.

Each mapper runs in its own child process, which reports its own peak resident set
(``VmHWM``; ``os.wait4``'s ``ru_maxrss`` would include the forking pytest worker's
memory), printed with the time (run with ``-s`` to see the numbers).
Measured 2026-11 on the project machine (2 cores): see CATALOGUE.md.
"""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from alte.paths import REPO_ROOT

REPO = REPO_ROOT
POINTS = 10_000_000
#: Far below the machine's 24 GiB, so four engineers' jobs still fit beside it.
BUDGET_GIB = 6.0

CHILD = """
import json, sys, time
import numpy as np
from alte.mappers import make_mapper
from alte.paths import REPO_ROOT
name, n = sys.argv[1], int(sys.argv[2])
rng = np.random.default_rng(0)
xy = rng.uniform(0.0, 100.0, (n, 2))
z = 0.5 * np.sin(xy[:, 0] / 7.0) + 0.3 * np.cos(xy[:, 1] / 5.0) + rng.normal(0.0, 0.02, n)
z[(np.abs(xy[:, 0] - 50.0) < 5.0) & (np.abs(xy[:, 1] - 50.0) < 5.0)] += 3.0  # an obstacle
points = np.column_stack([xy, z])
del xy, z
mapper = make_mapper(name)
start = time.perf_counter()
mapper.build(points, np.array([50.0, 50.0, 30.0]))
cells = mapper.cells()
with open("/proc/self/status") as status:
    hwm_kib = int(next(line.split()[1] for line in status if line.startswith("VmHWM:")))
print(json.dumps({"seconds": time.perf_counter() - start, "cells": len(cells), "hwm_kib": hwm_kib,
                  "occupied": int(cells.occupied.sum()),
                  "basis_functions": int(mapper.basis_functions)}))
"""


@pytest.mark.full
@pytest.mark.slow
@pytest.mark.parametrize("mapper", ["quadtree", "alte2d", "alte3d", "octomap"])
def test_ten_million_points_fit_in_memory(mapper):
    proc = subprocess.run([sys.executable, "-c", CHILD, mapper, str(POINTS)], cwd=REPO,
                          capture_output=True, text=True, check=False)
    assert proc.returncode == 0, proc.stderr[-2000:]
    result = json.loads(proc.stdout)
    peak_gib = result["hwm_kib"] / 2**20
    print(f"\n{mapper}: {POINTS} points, build {result['seconds']:.1f} s, "
          f"peak RSS {peak_gib:.2f} GiB, {result['basis_functions']} basis functions, "
          f"{result['occupied']} occupied")
    assert result["occupied"] > 0 and result["cells"] > 0
    assert peak_gib < BUDGET_GIB
