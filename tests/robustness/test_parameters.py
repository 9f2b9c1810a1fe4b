"""Out-of-range, unknown and misspelt parameters through ``alte map --set`` and ``alte report``.

Every row: exit code 2 and one stderr line that names the mapper and the parameter
with the rule it broke (or the valid names), before any input is read.
"""

from __future__ import annotations

import ast
from pathlib import Path

import nbformat
import numpy as np
import pytest

from alte.io.points.pointfiles import write_points
from alte.lab.report.plan import notebook_parameters
from alte.paths import REPO_ROOT

NOTEBOOKS = REPO_ROOT / "notebooks"

#: (mapper, --set value, what the error line must say)
OUT_OF_RANGE = [
    ("quadtree", "max_points=0", "quadtree: max_points=0 out of range (max_points >= 1)"),
    ("quadtree", "max_depth=25", "quadtree: max_depth=25 out of range (0 <= max_depth <= 24)"),
    ("quadtree", "max_depth=-1", "quadtree: max_depth=-1 out of range"),
    ("quadtree", "height_threshold=-1", "quadtree: height_threshold=-1.0 out of range"),
    ("quadtree", "height_threshold=nan", "quadtree: height_threshold=nan must be finite"),
    ("quadtree", "occupancy=median", "quadtree: occupancy='median' out of range (mean|max)"),
    ("quadtree", "ground=0,0,0,1", "quadtree: ground='0,0,0,1' out of range"),
    ("quadtree", "max_points=abc", "quadtree: max_points='abc' is not a valid int"),
    ("alte2d", "kappa=-1", "alte2d: kappa=-1.0 out of range (kappa > 0)"),
    ("alte2d", "kappa=0", "alte2d: kappa=0.0 out of range (kappa > 0)"),
    ("alte2d", "max_res=21", "alte2d: max_res=21 out of range (0 <= max_res <= 20)"),
    ("alte2d", "max_res=1e9", "alte2d: max_res=1000000000 out of range"),
    ("alte2d", "max_res=-1", "alte2d: max_res=-1 out of range"),
    ("alte2d", "min_pts=0", "alte2d: min_pts=0 out of range (min_pts >= 1)"),
    ("alte2d", "criterion=x", "alte2d: criterion='x' out of range (thesis|binev)"),
    ("octomap", "resolution=0", "octomap: resolution=0.0 out of range (> 0)"),
    ("octomap", "resolution=-5", "octomap: resolution=-5.0 out of range (> 0)"),
    ("octomap", "resolution=inf", "octomap: resolution=inf must be finite"),
    ("octomap", "max_range=0", "octomap: max_range=0.0 out of range (> 0, or -1 = unlimited)"),
    ("octomap", "prob_hit=0.4", "octomap: prob_hit=0.4 out of range (0.5 < p < 1)"),
    ("octomap", "prob_miss=0.6", "octomap: prob_miss=0.6 out of range (0 < p < 0.5)"),
    ("octomap", "clamp_min=0.7", "octomap: clamp_min=0.7 out of range (0 < p < 0.5)"),
    ("octomap", "occupancy_threshold=1", "octomap: occupancy_threshold=1.0 out of range"),
    ("octomap", "backend=x", "octomap: backend='x' out of range (native|reference)"),
    ("octomap", "sensor_model=x", "octomap: sensor_model='x' out of range (matlab|octomap)"),
    ("alte3d", "max_res=17", "alte3d: max_res=17 out of range (0 <= max_res <= 16)"),
    ("alte3d", "max_res=-1", "alte3d: max_res=-1 out of range"),
    ("alte3d", "min_pts=0", "alte3d: min_pts=0 out of range (>= 1)"),
    ("alte3d", "min_pts_split=0", "alte3d: min_pts_split=0 out of range (>= 1)"),
    ("alte3d", "occupancy_level=17", "alte3d: occupancy_level=17 out of range"),
    ("alte3d", "cell_height=0", "alte3d: cell_height=0.0 out of range (> 0)"),
]


@pytest.fixture(scope="module")
def cloud(tmp_path_factory: pytest.TempPathFactory) -> Path:
    rng = np.random.default_rng(0)
    path = tmp_path_factory.mktemp("cloud") / "c.npz"
    return write_points(path, rng.uniform(0.0, 10.0, (300, 3)))


@pytest.mark.parametrize("case", OUT_OF_RANGE, ids=[f"{m}-{s}" for m, s, _ in OUT_OF_RANGE])
def test_mapper_parameter_out_of_range(bags, capsys, cloud, tmp_path, case):
    mapper, setting, message = case
    code, out, err = bags.run_cli(capsys, "map", cloud, "--mapper", mapper, "--set", setting,
                                  "--export", tmp_path / "cells.npz")
    assert code == 2 and out == ""
    assert message in bags.one_line_error(err, "map")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("mapper", ["quadtree", "octomap", "alte2d", "alte3d"])
def test_unknown_set_key_lists_the_valid_ones(bags, capsys, cloud, mapper):
    from alte.mappers import make_mapper

    code, _, err = bags.run_cli(capsys, "map", cloud, "--mapper", mapper, "--set", "resolutoin=2")
    line = bags.one_line_error(err, "map")
    assert code == 2 and f"{mapper}: unknown parameter(s) resolutoin; valid: " in line
    assert line.endswith(", ".join(sorted(make_mapper(mapper).params.names())))


def test_unknown_mapper_name(bags, capsys, cloud):
    code, _, err = bags.run_cli(capsys, "map", cloud, "--mapper", "octree")
    line = bags.one_line_error(err, "map")
    assert code == 2 and "unknown mapper 'octree'; valid: quadtree, octomap, alte2d, alte3d" in line


@pytest.mark.parametrize(("value", "message"), [
    ("0,0,-1", "--domain '0,0,-1': expected auto, control, data or numbers"),
    ("garbage", "--domain 'garbage': expected auto, control, data or numbers"),
    ("control", "the input has no control volume"),
])
def test_bad_domain(bags, capsys, cloud, value, message):
    code, _, err = bags.run_cli(capsys, "map", cloud, "--mapper", "alte3d", f"--domain={value}")
    assert code == 2 and message in bags.one_line_error(err, "map")


def test_fractional_integer_parameter_is_rejected(bags, capsys, cloud):
    code, _, err = bags.run_cli(capsys, "map", cloud, "--mapper", "quadtree",
                                "--set", "max_points=2.5")
    assert code == 2 and "max_points='2.5'" in err


def test_octomap_key_space_bounds_the_finest_resolution(bags, capsys, cloud, tmp_path):
    """``max_res beyond what the key type holds`` for Octomap: 2^16 voxels per axis.

    Octomap has no depth parameter (16 levels, fixed), so a too fine ``resolution``
    shrinks the key space below the data; OctoMap then skips the rays, like the C++
    library. This documents what the user sees today (see CATALOGUE.md).
    """
    code, out, err = bags.run_cli(capsys, "map", cloud, "--mapper", "octomap",
                                  "--set", "resolution=1e6", "--json")
    assert code == 0, err
    assert '"occupied_cells": 0' in out and '"points": 300' in out


# ------------------------------------------------------------------ notebook parameters


def test_misspelt_notebook_parameter(bags, capsys, tmp_path):
    code, out, err = bags.run_cli(capsys, "report", "--quick", "--param", "TERAIN=sim_nav_1",
                                  "--out", tmp_path / "reports", "--data", tmp_path / "data")
    line = bags.one_line_error(err, "report")
    assert code == 2 and out == ""
    assert "unknown notebook parameter TERAIN; valid parameters: " in line and "TERRAIN" in line
    assert not (tmp_path / "reports").exists() and not (tmp_path / "data").exists()


@pytest.mark.parametrize("name", ["OUT_DIR", "DATA_DIR"])
def test_runner_owned_notebook_parameter(bags, capsys, tmp_path, name):
    code, _, err = bags.run_cli(capsys, "report", "--quick", "--param", f"{name}=/tmp/x",
                                "--out", tmp_path / "reports")
    assert code == 2
    line = bags.one_line_error(err, "report")
    assert f"--param: notebook parameter {name}: set by the runner" in line


def _assigned(notebook: Path) -> set[str]:
    nb = nbformat.read(notebook, as_version=4)
    cell = next(c for c in nb.cells if "parameters" in c.metadata.get("tags", []))
    tree = ast.parse(cell.source)
    return {t.id for node in tree.body if isinstance(node, ast.Assign) for t in node.targets
            if isinstance(t, ast.Name)}


@pytest.mark.parametrize("notebook", sorted(NOTEBOOKS.glob("*.ipynb")), ids=lambda p: p.stem)
def test_every_notebook_parameter_can_be_set(notebook):
    """Each name of the ``parameters`` cell is seen by papermill, so ``--param`` accepts it."""
    assert set(notebook_parameters(notebook)) == _assigned(notebook)
