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


def _loaded(modules: list[str]) -> list[str]:
    code = (f"import importlib, json, sys\nfor m in {modules!r}: importlib.import_module(m)\n"
            f"print(json.dumps([h for h in {HEAVY!r} if h in sys.modules]))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True, timeout=120).stdout
    loaded: list[str] = json.loads(out)
    return loaded


def test_map_path_imports_no_heavy_stack() -> None:
    assert _loaded(MAP_PATH) == []


def test_control_a_study_module_that_needs_open3d_shows_up() -> None:
    """The check itself: a study module that uses open3d at import time is seen."""
    assert _loaded(["alte.studies.landing.truth"]) == ["open3d"]
