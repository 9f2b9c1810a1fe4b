"""Map messages: rasterised 2D maps, grid_map's index convention, cube lists, Octomap."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from alte.errors import ParameterError
from alte.export.maps import (
    CUBE_LIST,
    DELETEALL,
    cell_markers,
    grid_map,
    height_colours,
    occupancy_grid,
    octomap_msg,
    raster,
    shown_cells,
)
from alte.mappers import Cells, Octomap
from alte.mappers.octomap import read_bt


def two_level_cells() -> Cells:
    """A 4 m x 4 m map: one 2 m cell (height 1, occupied), three 1 m cells, one unknown."""
    centers = np.array([[1.0, 1.0, 1.0], [2.5, 0.5, 0.2], [3.5, 0.5, 0.4], [2.5, 1.5, 0.6],
                        [3.5, 1.5, np.nan], [1.0, 3.0, 0.0], [3.0, 3.0, 2.0]])
    edge = np.array([2.0, 1.0, 1.0, 1.0, 1.0, 2.0, 2.0])
    sizes = np.column_stack([edge, edge, np.zeros(7)])
    occupied = np.array([True, False, False, False, False, False, True])
    return Cells(centers, sizes, centers[:, 2], occupied, np.array([1, 2, 2, 2, 2, 1, 1]))


def test_raster_paints_every_leaf_at_the_finest_size() -> None:
    grid = raster(two_level_cells(), np.array([10.0, 20.0, 0.0]))
    assert grid.resolution == 1.0 and grid.shape == (4, 4)
    assert grid.origin.tolist() == [10.0, 20.0]
    assert (grid.height[:2, :2] == 1.0).all() and (grid.occupancy[:2, :2] == 100).all()
    assert grid.height[0, 2] == 0.2 and grid.height[1, 2] == 0.6
    assert np.isnan(grid.height[1, 3]) and grid.occupancy[1, 3] == -1
    assert (grid.height[2:, 2:] == 2.0).all() and (grid.occupancy[2:, :2] == 0).all()


def test_raster_coarsens_to_fit_and_refuses_an_empty_map() -> None:
    assert raster(two_level_cells(), np.zeros(3), max_cells=4).resolution == 2.0
    cells = two_level_cells()
    unknown = Cells(np.full((1, 3), np.nan), np.ones((1, 3)), np.zeros(1), np.zeros(1, bool),
                    np.zeros(1, np.int64))
    with pytest.raises(ParameterError, match="no known cell"):
        raster(unknown, np.zeros(3))
    with pytest.raises(ParameterError, match="max_cells=0"):
        raster(cells, np.zeros(3), max_cells=0)


def test_occupancy_grid_is_row_major_from_its_origin() -> None:
    msg = occupancy_grid(raster(two_level_cells(), np.zeros(3)), 5_000_000_001, "map")
    assert (msg.info.width, msg.info.height, msg.info.resolution) == (4, 4, 1.0)
    assert msg.header.stamp.sec == 5 and msg.header.stamp.nanosec == 1
    data = msg.data.reshape(4, 4)
    assert data[0, 0] == 100 and data[1, 3] == -1 and data[0, 2] == 0


def test_grid_map_follows_grid_map_index_convention() -> None:
    """grid_map: index (0, 0) is the cell at max x, max y; rows run along -x, columns along
    -y; storage is column-major with the outer dimension labelled column_index."""
    grid = raster(two_level_cells(), np.zeros(3))
    msg = grid_map(grid, 0, "map")
    assert msg.layers == ["elevation", "occupancy"]
    assert msg.info.resolution == 1.0 and msg.info.length_x == 4.0 and msg.info.length_y == 4.0
    assert (msg.info.pose.position.x, msg.info.pose.position.y) == (2.0, 2.0)
    layer = msg.data[0]
    dims = [(d.label, d.size, d.stride) for d in layer.layout.dim]
    assert dims == [("column_index", 4, 16), ("row_index", 4, 4)]

    def at(x: float, y: float) -> float:
        i = int((2.0 + 4.0 / 2 - x) // 1.0)  # grid_map: index from the map's max corner
        j = int((2.0 + 4.0 / 2 - y) // 1.0)
        return float(layer.data[j * 4 + i])

    assert at(0.5, 0.5) == 1.0 and at(2.5, 0.5) == pytest.approx(0.2)
    assert at(2.5, 1.5) == pytest.approx(0.6) and np.isnan(at(3.5, 1.5))
    assert at(3.5, 3.5) == 2.0 and at(0.5, 3.5) == 0.0


def test_cell_markers_group_sizes_and_colour_by_height() -> None:
    cells = two_level_cells()
    mask = shown_cells(cells, 2)
    assert mask.sum() == 6
    msg = cell_markers(cells, mask, 7, "map", np.array([100.0, 0.0, 0.0]))
    assert msg.markers[0].action == DELETEALL
    cubes = msg.markers[1:]
    assert [m.type for m in cubes] == [CUBE_LIST, CUBE_LIST]
    assert sorted(len(m.points) for m in cubes) == [3, 3]
    big = next(m for m in cubes if m.scale.x == 2.0)
    assert big.scale.z == pytest.approx(0.1)
    top = max(range(len(big.points)), key=lambda k: big.points[k].z)
    assert (big.points[top].x, big.points[top].y, big.points[top].z) == (103.0, 3.0, 2.0)
    colour = big.colors[top]
    assert np.allclose([colour.r, colour.g, colour.b, colour.a], height_colours(
        np.array([0.0, 2.0]))[1])


def test_shown_cells_of_a_3d_map_are_the_occupied_ones() -> None:
    cells = two_level_cells()
    assert shown_cells(cells, 3).tolist() == cells.occupied.tolist()
    assert shown_cells(cells, 3, everything=True).sum() == 6
    assert height_colours(np.array([1.0, 1.0])).shape == (2, 4)


def test_octomap_message_is_the_bt_payload(tmp_path: Path) -> None:
    rng = np.random.default_rng(3)
    mapper = Octomap(resolution=4.0)
    mapper.insert(rng.uniform(-2, 2, (400, 3)) + np.array([0.0, 0.0, 3.0]), np.zeros(3))
    msg = octomap_msg(mapper, 1, "map")
    assert msg.binary and msg.id == "OcTree" and msg.resolution == 0.25
    bt = tmp_path / "map.bt"
    mapper.write_bt(bt)
    content = bt.read_bytes()
    assert content.endswith(msg.data.tobytes())
    rebuilt = tmp_path / "rebuilt.bt"
    rebuilt.write_bytes(content[: len(content) - len(msg.data)] + msg.data.tobytes())
    ours, theirs = mapper.cells(), read_bt(rebuilt)
    assert theirs.occupied.sum() > 0
    assert np.isclose(ours.sizes[ours.occupied, 0].__pow__(3).sum(),
                      theirs.sizes[theirs.occupied, 0].__pow__(3).sum())
