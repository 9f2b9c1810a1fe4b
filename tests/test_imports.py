"""The streaming path stays light: ``alte map BAG`` does not load the heavy optional stacks;
and the package has no import cycle.

open3d (~200 MB resident), pyvista/VTK and the odometry libraries are imported on
first use; a module-level import of one of them in a stage module would put it in
every ``alte map`` process and in the peak-RSS bench row (map plus a few frames).
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

from support.imports import cycles as _cycles
from support.imports import imports as _imports

#: Modules ``alte map BAG`` imports before it reads a scan.
#: (Modules, not only packages: ``alte.pipeline``, ``alte.io`` and ``alte.mappers`` load
#: their modules on first use.)
MAP_PATH = ["alte.cli", "alte.commands.map", "alte.pipeline.run", "alte.pipeline.prepare",
            "alte.io.bags.bag", "alte.io.points.pointfiles", "alte.registration",
            "alte.mappers.registry",
            "alte.export.run", "alte.metrics"]
HEAVY = ["open3d", "pyvista", "vtk", "kiss_icp", "small_gicp", "matplotlib", "dask"]


def _loaded(*stages: list[str]) -> list[list[str]]:
    """The heavy modules loaded after importing each stage's modules in turn (one child)."""
    code = ("import importlib, json, sys\nseen = []\n"
            f"for stage in {list(stages)!r}:\n"
            "    for m in stage: importlib.import_module(m)\n"
            f"    seen.append([h for h in {HEAVY!r} if h in sys.modules])\n"
            "print(json.dumps(seen))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True, timeout=600).stdout
    loaded: list[list[str]] = json.loads(out)
    return loaded


def test_map_path_imports_no_heavy_stack() -> None:
    """Nothing heavy after the map path; the check itself sees matplotlib once a lab
    module that draws with it at import time is loaded."""
    assert _loaded(MAP_PATH, ["alte.lab.plot.terrain"]) == [[], ["matplotlib"]]


def test_no_import_cycle_in_alte() -> None:
    """Data flows one way: no module of ``alte`` imports, at any depth and in any function,
    one that imports it back."""
    import alte

    graph = _imports(Path(alte.__file__).parent)
    assert "alte.pipeline.feed" in graph["alte.pipeline.run"]  # the graph is read
    assert "alte.mappers.registry" in graph["alte.mappers"]  # with the lazy packages' stubs
    assert _cycles(graph) == []


def test_the_cycle_check_finds_a_cycle() -> None:
    assert _cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
    assert _cycles({"a": {"b"}, "b": set()}) == []


#: Each mapper's own modules (one module, or the Octomap package); shared code lives in
#: alte.mappers.base / domain / _rows and the octree and quad packages.
MAPPER_MODULES = ("alte.mappers.quadtree", "alte.mappers.alte2d", "alte.mappers.alte3d",
                  "alte.mappers.octomap")


def _owner(module: str) -> str | None:
    return next((m for m in MAPPER_MODULES if module == m or module.startswith(m + ".")), None)


def test_no_mapper_imports_another_mappers_module() -> None:
    import alte

    graph = _imports(Path(alte.__file__).parent)
    crossing = sorted((a, b) for a, targets in graph.items() for b in targets
                      if _owner(a) and _owner(b) and _owner(a) != _owner(b))
    assert crossing == []
    assert {"alte.mappers.octomap.backends", "alte.mappers.octree.tree"} <= graph[
        "alte.mappers.octomap.mapper"]  # the family imports its own and shared modules


def test_the_ground_settings_load_without_the_ground_stage() -> None:
    """``alte map`` reads the ground filters' settings for its flags; importing them must not
    load the stage (pandas through the obstacle tables: +80 MB on every ``alte map``)."""
    code = ("import sys, json\nimport alte.commands.map, alte.ground.settings\n"
            "print(json.dumps([m for m in ('pandas', 'alte.ground.obstacles', "
            "'alte.ground.clustering') if m in sys.modules]))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True, timeout=600).stdout
    assert json.loads(out) == []
