"""Obstacle identification against a hand-built scene whose answers are known."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from alte.errors import MetricsError, ParameterError
from alte.lab.studies.obstacles import (
    OBSTACLE_COLUMNS,
    ObstacleSettings,
    identify,
    map_raster,
    object_table,
    obstacle_columns,
    obstacle_options,
    obstacles_table,
    true_obstacles,
    write_obstacle_tables,
)
from alte.mappers.base import Cells
from alte.metrics import TrueSurface
from alte.sim import SceneBuilder
from alte.types import Box

OPTIONS = ObstacleSettings(min_height=0.3, step=0.25, slack=1)
BOUNDS = Box.of((-10.0, -10.0, -1.0, 10.0, 10.0, 8.0))


def _surface(classes: bool = True) -> TrueSurface:
    """Ground; a 2 x 2 x 1 m box at (5, 5); a 10 cm post 1.5 m tall at (-5, -5); a 5 cm
    high slab at (0, -6); a 1 m pillar under a 4 x 4 m canopy at 3 m over (-5, 5)."""
    b = SceneBuilder()
    b.ground("ground", (-30.0, -30.0, 30.0, 30.0))
    b.slab("box", "building", (5.0, 5.0), (2.0, 2.0), z=(0.0, 1.0))
    b.slab("post", "fence", (-5.0, -5.0), (0.1, 0.1), z=(0.0, 1.5))
    b.slab("low", "debris", (0.0, -6.0), (1.0, 1.0), z=(0.0, 0.05))
    b.slab("pillar", "pillar", (-5.0, 5.0), (0.5, 0.5), z=(0.0, 3.0))
    b.slab("canopy", "overhang", (-5.0, 5.0), (4.0, 4.0), z=(3.0, 3.2))
    scene = b.build()
    return TrueSurface(scene.vertices, scene.triangles, scene.object_ids, scene.labels,
                       scene.classes if classes else None)


@pytest.fixture(scope="module")
def truth():
    return true_obstacles(_surface(), BOUNDS, OPTIONS)


def _cells_2d(heights: dict[tuple[float, float], float], edge: float = 1.0) -> Cells:
    """A 2D map of ``edge`` cells tiling the bounds, at 0 m except ``heights`` (by the
    cell's lower-left corner)."""
    xs = np.arange(-10.0, 10.0, edge)
    corners = np.array([(x, y) for x in xs for y in xs])
    z = np.array([heights.get((float(x), float(y)), 0.0) for x, y in corners])
    centers = np.column_stack([corners + edge / 2, z])
    sizes = np.column_stack([np.full((len(z), 2), edge), np.zeros(len(z))])
    return Cells(centers, sizes, z, z > 0.3, np.zeros(len(z), int))


def test_true_obstacles_are_the_tall_objects_seen_from_above(truth):
    assert truth.names == ("box", "post", "canopy")
    assert truth.hidden == ("pillar",)  # under the canopy: no top-down map can show it
    assert truth.heights == pytest.approx([1.0, 1.5, 3.2])
    assert truth.ground == pytest.approx(0.0)
    assert truth.grid.shape == (80, 80)
    assert len(truth.footprints[0]) == 81  # 2 m x 2 m in 0.25 m pixels, edges touching too
    assert 1 <= len(truth.footprints[1]) <= 4  # thinner than a pixel, still there
    assert all(len(n) > len(f) for n, f in zip(truth.near, truth.footprints, strict=True))


def test_truth_needs_classes_and_checks_its_options():
    with pytest.raises(MetricsError, match="no object classes"):
        true_obstacles(_surface(classes=False), BOUNDS, OPTIONS)
    b = SceneBuilder()
    b.slab("roof", "building", (0.0, 0.0), (40.0, 40.0), z=(0.0, 2.0))  # covers everything
    scene = b.build()
    roofed = TrueSurface(scene.vertices, scene.triangles, scene.object_ids, scene.labels,
                         scene.classes)
    with pytest.raises(MetricsError, match="no pixel sees the ground"):
        true_obstacles(roofed, BOUNDS, OPTIONS)
    with pytest.raises(ParameterError, match="min_height=0"):
        ObstacleSettings(min_height=0.0)
    assert obstacle_options("exp_lan_1") == ObstacleSettings(min_height=0.06, step=0.05)
    assert obstacle_options("sim_nav_1") == ObstacleSettings(min_height=0.3, step=0.25)


def test_a_2d_map_finds_what_stands_up_and_pays_for_what_is_not_there(truth):
    cells = _cells_2d({(5.0, 5.0): 0.9, (4.0, 4.0): 0.9, (-6.0, 4.0): 3.0, (-5.0, 5.0): 3.1,
                       (8.0, -9.0): 2.0})  # box (two cells), canopy, a phantom
    scores = identify(map_raster(cells, 2, truth.grid, OPTIONS.min_height), truth)
    assert (scores.true, scores.found, scores.map_obstacles, scores.map_there) == (3, 2, 3, 2)
    assert scores.recall == pytest.approx(2 / 3) and scores.precision == pytest.approx(2 / 3)
    objects = scores.objects.set_index("object")
    assert objects["found"].to_dict() == {"box": True, "post": False, "canopy": True}
    assert objects.loc["box", "height_error_m"] == pytest.approx(-0.1)
    assert objects.loc["canopy", "height_error_m"] == pytest.approx(-0.1)
    assert scores.height_bias_m == pytest.approx(-0.1)
    assert scores.area_precision == pytest.approx(1 - 16 / (4 * 16 + 16))  # phantom: 1 cell


def test_a_low_step_is_no_obstacle_and_a_cell_off_the_footprint_misses(truth):
    low = _cells_2d({(0.0, -7.0): 0.2})  # 20 cm: below min_height
    scores = identify(map_raster(low, 2, truth.grid, OPTIONS.min_height), truth)
    assert scores.found == 0 and scores.map_obstacles == 0
    assert np.isnan(scores.precision) and np.isnan(scores.height_error_m)
    off = _cells_2d({(-7.0, -7.0): 1.4})  # 0.95 m from the post: beyond one pixel of slack
    assert identify(map_raster(off, 2, truth.grid, 0.3), truth).found == 0
    near = _cells_2d({(-6.0, -6.0): 1.4})  # ends at -5 m, the post begins at -5.05 m
    assert identify(map_raster(near, 2, truth.grid, 0.3), truth).found == 1


def _voxels(centres: list[tuple[float, float, float]], edge: float) -> Cells:
    c = np.array(centres, dtype=float)
    return Cells(c, np.full(c.shape, edge), np.ones(len(c)), np.ones(len(c), bool),
                 np.zeros(len(c), int))


def test_a_3d_map_states_heights_only_to_within_its_cells(truth):
    ground = [(x + 0.25, y + 0.25, 0.25 if (x + y) % 2 else -0.25)
              for x in np.arange(-10, 10, 0.5) for y in np.arange(-10, 10, 0.5)]
    thin = _voxels([*ground, (-4.95, -4.95, 1.25)], 0.5)  # one 0.5 m voxel over the post
    scores = identify(map_raster(thin, 3, truth.grid, OPTIONS.min_height), truth)
    assert scores.map_obstacles == 1 and scores.found == 1  # ground steps of one edge: none
    post = scores.objects.set_index("object").loc["post"]
    assert post["map_height_m"] == pytest.approx(1.25 - 0.25)  # over the median ground voxel
    assert identify(map_raster(_voxels([(5.0, 5.0, 0.5)], 2.0), 3, truth.grid, 0.3),
                    truth).found == 0  # a lone 2 m voxel: no ground, no step


def test_tables_from_grid_rows(truth, tmp_path):
    cells = _cells_2d({(5.0, 5.0): 0.9})
    scores = identify(map_raster(cells, 2, truth.grid, OPTIONS.min_height), truth)
    row = {"terrain": "sim_lan_1", "case": "lan", "mapper": "quadtree",
           "params": json.dumps({"max_points": 25}), "seed": 0, "basis_functions": 400,
           **obstacle_columns(scores)}
    grid = pd.DataFrame([row, {**row, "seed": 1}, {**row, "mapper": "alte2d",
                                                     "obstacles_true": 0}])
    table = obstacles_table(grid)
    assert list(table.columns) == list(OBSTACLE_COLUMNS) and len(table) == 2
    assert table["setting"].iloc[0] == "max_points=25" and table["hidden"].iloc[0] == "pillar"
    assert table["recall"].iloc[0] == pytest.approx(1 / 3)
    objects = object_table(grid)
    assert len(objects) == 6 and set(objects["object_id"]) == set(truth.ids.tolist())
    assert obstacle_columns(None) == {}
    paths = write_obstacle_tables(grid, tmp_path)
    assert [p.name for p in paths] == ["obstacles.csv", "obstacle_objects.csv"]
    assert write_obstacle_tables(grid.drop(columns="obstacles_true"), tmp_path / "no") == []
