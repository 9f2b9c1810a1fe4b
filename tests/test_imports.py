"""The streaming path stays light: ``alte map BAG`` does not load the heavy optional stacks.

open3d (~200 MB resident), pyvista/VTK and the odometry libraries are imported on
first use; a module-level import of one of them in a stage module would put it in
every ``alte map`` process and in the peak-RSS bench row (map plus a few frames).
"""

from __future__ import annotations

import json
import subprocess
import sys

#: Modules ``alte map BAG`` imports before it reads a scan.
MAP_PATH = ["alte.cli", "alte.commands.map", "alte.pipeline", "alte.io", "alte.registration",
            "alte.mappers", "alte.metrics"]
HEAVY = ["open3d", "pyvista", "vtk", "kiss_icp", "small_gicp", "matplotlib", "dask"]


def _loaded(*stages: list[str]) -> list[list[str]]:
    """The heavy modules loaded after importing each stage's modules in turn (one child)."""
    code = ("import importlib, json, sys\nseen = []\n"
            f"for stage in {list(stages)!r}:\n"
            "    for m in stage: importlib.import_module(m)\n"
            f"    seen.append([h for h in {HEAVY!r} if h in sys.modules])\n"
            "print(json.dumps(seen))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True, timeout=120).stdout
    loaded: list[list[str]] = json.loads(out)
    return loaded


def test_map_path_imports_no_heavy_stack() -> None:
    """Nothing heavy after the map path; the check itself sees open3d once a study module
    that uses it at import time is loaded."""
    assert _loaded(MAP_PATH, ["alte.studies.landing.truth"]) == [[], ["open3d"]]
