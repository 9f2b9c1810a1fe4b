"""Map messages: rasterised maps, occupancy by the landing criterion, grid_map's index
convention, Foxglove grids, cube lists, Octomap."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from alte.errors import ParameterError
from alte.export.grids import (
    GRID_FIELDS,
    foxglove_grid,
    grid_cells,
    grid_map,
    height_colours,
    occupancy_grid,
    raster,
)
from alte.export.maps import CUBE_LIST, DELETEALL, cell_markers, octomap_msg, shown_cells
from alte.export.rosmsg import typestore
from alte.ground.surface import OccupancySettings
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
    assert (grid.height[:2, :2] == 1.0).all()
    assert grid.height[0, 2] == 0.2 and grid.height[1, 2] == 0.6
    assert np.isnan(grid.height[1, 3]) and grid.occupancy[1, 3] == -1
    assert (grid.height[2:, 2:] == 2.0).all() and (grid.height[2:, :2] == 0.0).all()
    known = np.isfinite(grid.height)
    assert set(np.unique(grid.occupancy[known])) <= {0, 100}
    assert (grid.occupancy[~known] == -1).all()  # -1 only where no leaf lies


def grid_of_two_levels():
    return raster(two_level_cells(), np.zeros(3))


def flat_with_a_box(size: int = 40) -> Cells:
    """A 40 m x 40 m flat 2D map of 1 m cells at height 5 with a 4 m x 4 m, 2 m tall box,
    a 30 deg ramp beyond x = 30 and one unknown cell."""
    ij = np.stack(np.meshgrid(np.arange(size), np.arange(size), indexing="ij"), -1).reshape(-1, 2)
    centers = np.column_stack([ij[:, 1] + 0.5, ij[:, 0] + 0.5, np.full(len(ij), 5.0)])
    box = (np.abs(centers[:, 0] - 10) < 2) & (np.abs(centers[:, 1] - 10) < 2)
    centers[box, 2] = 7.0
    ramp = centers[:, 0] > 30  # 30 deg slope along x
    centers[ramp, 2] = 5.0 + np.tan(np.radians(30.0)) * (centers[ramp, 0] - 30)
    centers[(ij[:, 0] == 20) & (ij[:, 1] == 20), 2] = np.nan
    sizes = np.column_stack([np.ones(len(ij)), np.ones(len(ij)), np.zeros(len(ij))])
    return Cells(centers, sizes, centers[:, 2], np.ones(len(ij), bool), np.zeros(len(ij), int))


@pytest.mark.parametrize("ground", ["local", "plane"])
def test_occupancy_tells_landable_ground_from_obstacles_and_slopes(ground: str) -> None:
    grid = raster(flat_with_a_box(), np.zeros(3), rule=OccupancySettings(ground=ground))
    occ = grid.occupancy
    assert occ[20, 20] == -1 and (occ == -1).sum() == 1
    assert (occ[8:12, 8:12] == 100).all()  # the box
    assert occ[30, 20] == 0 and occ[5, 25] == 0  # open flat ground
    assert (occ[:, 34:] == 100).all()  # the 30 deg ramp
    assert (occ[20, 21:23] == 0).all()  # an unknown neighbour does not spoil flat ground
    steep = raster(flat_with_a_box(), np.zeros(3), rule=OccupancySettings(max_slope_deg=45.0))
    assert (steep.occupancy[:, 34:] == 0).all()  # a steeper vehicle limit frees the ramp


def test_a_3d_map_is_classified_on_its_top_occupied_surface() -> None:
    """Columns: flat ground leaves (occupied) under free air leaves; a 3 m pillar; one column
    seen only as free space; nothing beyond x = 20."""
    cx, cy = np.meshgrid(np.arange(20) + 0.5, np.arange(20) + 0.5)
    cx, cy = cx.ravel(), cy.ravel()
    ground = np.column_stack([cx, cy, np.full(cx.size, 0.5)])
    air = np.column_stack([cx, cy, np.full(cx.size, 1.5)])
    occupied = np.r_[np.ones(cx.size, bool), np.zeros(cx.size, bool)]
    centers = np.vstack([ground, air])
    pillar = np.array([[10.5, 10.5, 1.5], [10.5, 10.5, 2.5]])
    hole = (cx == 3.5) & (cy == 15.5)
    occupied[: cx.size][hole] = False  # that column is free all the way down
    centers, occupied = np.vstack([centers, pillar]), np.r_[occupied, True, True]
    cells = Cells(centers, np.ones_like(centers), np.zeros(len(centers)), occupied,
                  np.zeros(len(centers), int))
    grid = raster(cells, np.zeros(3), dims=3)
    assert grid.shape == (20, 20) and grid.height[10, 10] == 3.0 and grid.height[0, 0] == 1.0
    assert np.isnan(grid.height[15, 3]) and grid.occupancy[15, 3] == 100
    assert grid.occupancy[10, 10] == 100 and grid.occupancy[2, 2] == 0
    assert not (grid.occupancy == -1).any()


def test_foxglove_grid_packs_height_occupancy_and_colours() -> None:
    grid = grid_of_two_levels()
    msg = foxglove_grid(grid, 3_000_000_000, "map")
    kinds = typestore().types["foxglove_msgs/msg/PackedElementField"]
    assert [(f.name, f.offset, f.type) for f in msg.fields] == [
        ("elevation", 0, kinds.FLOAT32), ("occupancy", 4, kinds.INT8), ("red", 5, kinds.UINT8),
        ("green", 6, kinds.UINT8), ("blue", 7, kinds.UINT8), ("alpha", 8, kinds.UINT8)]
    assert [f[0] for f in GRID_FIELDS] == [f.name for f in msg.fields]
    assert (msg.column_count, msg.cell_stride, msg.row_stride) == (4, 9, 36)
    assert len(msg.data) == 4 * 36 and msg.timestamp.sec == 3 and msg.frame_id == "map"
    assert (msg.cell_size.x, msg.cell_size.y) == (1.0, 1.0)
    assert msg.pose.position.z == -1.5 and msg.pose.position.x == 0.0
    # decode the bytes independently: row-major from the origin corner, little-endian
    raw = np.asarray(msg.data, dtype=np.uint8).reshape(4, 4, 9)
    elevation = raw[..., 0:4].copy().view("<f4")[..., 0]
    assert np.allclose(elevation, grid.height, equal_nan=True)
    assert (raw[..., 4].view(np.int8) == grid.occupancy).all()
    assert raw[1, 3, 8] == 0 and (raw[..., 8][np.isfinite(grid.height)] == 255).all()
    top = np.argwhere(grid.height == 2.0)[0]
    assert np.allclose(raw[top[0], top[1], 5:8] / 255, height_colours(np.array([0.0, 2.0]))[1, :3],
                       atol=1 / 255)
    assert grid_cells(grid).shape == (4, 4)


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
    assert data.tolist() == grid_of_two_levels().occupancy.tolist() and data[1, 3] == -1
    assert msg.info.origin.position.z == -1.0  # one cell below the lowest height (0 m)


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


def test_a_variance_layer_goes_out_in_grid_map_and_the_foxglove_grid() -> None:
    """The cells' variance (the elevation map's) is painted like the height, becomes a
    grid_map layer and a float32 Foxglove field after alpha (NaN where unknown)."""
    cells = two_level_cells()
    variance = np.arange(7, dtype=np.float64) / 100
    cells = Cells(cells.centers, cells.sizes, cells.value, cells.occupied, cells.level,
                  {"variance": variance})
    grid = raster(cells, np.zeros(3))
    assert list(grid.layers) == ["variance"] and grid.layers["variance"][0, 0] == 0.0
    assert grid.layers["variance"][3, 3] == 0.06 and np.isnan(grid.layers["variance"][1, 3])
    msg = grid_map(grid, 1, "map")
    assert msg.layers == ["elevation", "occupancy", "variance"] and len(msg.data) == 3
    fox = foxglove_grid(grid, 1, "map")
    assert [(f.name, f.offset) for f in fox.fields][-1] == ("variance", 9)
    assert fox.cell_stride == 13 and fox.row_stride == 4 * 13
    raw = np.asarray(fox.data, dtype=np.uint8).reshape(4, 4, 13)
    decoded = raw[..., 9:13].copy().view("<f4")[..., 0]
    assert np.allclose(decoded, grid.layers["variance"], equal_nan=True)
    assert raster(cells, np.zeros(3), dims=3).layers == {}  # 3D maps: no layer painted
