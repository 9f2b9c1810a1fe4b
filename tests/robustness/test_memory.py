"""A 10^7-point cloud maps with every mapper within the 24 GiB, 2-core machine.

Each mapper runs in its own child process; ``os.wait4`` gives that child's peak
resident set size, printed with the time (run with ``-s`` to see the numbers).
Measured 2026-11 on the project machine (2 cores): see CATALOGUE.md.
"""

from __future__ import annotations

import json
import os
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
print(json.dumps({"seconds": time.perf_counter() - start, "cells": len(cells),
                  "occupied": int(cells.occupied.sum()),
                  "basis_functions": int(mapper.basis_functions)}))
"""


@pytest.mark.slow
@pytest.mark.parametrize("mapper", ["quadtree", "alte2d", "alte3d", "octomap"])
def test_ten_million_points_fit_in_memory(mapper):
    proc = subprocess.Popen([sys.executable, "-c", CHILD, mapper, str(POINTS)], cwd=REPO,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    _, status, usage = os.wait4(proc.pid, 0)
    out, err = proc.stdout.read(), proc.stderr.read()
    proc.returncode = os.waitstatus_to_exitcode(status)
    assert proc.returncode == 0, err[-2000:]
    result = json.loads(out)
    peak_gib = usage.ru_maxrss / 2**20  # Linux reports KiB
    print(f"\n{mapper}: {POINTS} points, build {result['seconds']:.1f} s, "
          f"peak RSS {peak_gib:.2f} GiB, {result['basis_functions']} basis functions, "
          f"{result['occupied']} occupied")
    assert result["occupied"] > 0 and result["cells"] > 0
    assert peak_gib < BUDGET_GIB
