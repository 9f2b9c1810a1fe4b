"""The grids of an exported MCAP, decoded with mcap_ros2, against a map drawn by hand.

No function of the exporter computes the expected values: the 8 x 6 m map below is
written cell by cell and its grids are written out pixel by pixel.
"""

from __future__ import annotations

from pathlib import Path
from typing import cast

import numpy as np
from support.mcapfiles import read_back

from alte.export import McapFile
from alte.export.run import ExportSettings, MapExporter
from alte.mappers import Cells, Mapper
from alte.types import RegisteredFrame

NAN = np.nan
#: Heights by row (y, from the south edge) and column (x, from the west edge), 1 m cells:
#: flat ground at 3 m, a 2 x 2 m block 2 m tall, one 2 m leaf at 3 m, one unknown cell.
HEIGHT = np.array([[3.0, 3.0, 3.0, 3.0, 3.0, 3.0, 3.0, 3.0],
                   [3.0, 3.0, 3.0, 3.0, 3.0, 3.0, 3.0, 3.0],
                   [3.0, 3.0, 3.0, 3.0, 5.0, 5.0, 3.0, 3.0],
                   [3.0, 3.0, 3.0, 3.0, 5.0, 5.0, 3.0, NAN],
                   [3.0, 3.0, 3.0, 3.0, 3.0, 3.0, 3.0, 3.0],
                   [3.0, 3.0, 3.0, 3.0, 3.0, 3.0, 3.0, 3.0]])
SHIFT = np.array([100.0, 200.0, 0.0])   # the map's local origin in the world


class HandMap:
    """A 2D map whose leaves are given: 1 m cells, but one 2 m leaf over x 0-2, y 4-6."""

    dims = 2

    def cells(self) -> Cells:
        rows, cols = np.nonzero(np.ones_like(HEIGHT, bool))
        big = (rows >= 4) & (cols < 2)
        centers = np.column_stack([cols + 0.5, rows + 0.5, HEIGHT[rows, cols]])[~big]
        centers = np.vstack([centers, [1.0, 5.0, 3.0]])
        edge = np.r_[np.ones(int((~big).sum())), 2.0]
        n = len(centers)
        return Cells(centers, np.column_stack([edge, edge, np.zeros(n)]), centers[:, 2],
                     np.isfinite(centers[:, 2]), np.zeros(n, np.int64))


def _export(path: Path) -> dict[str, list[tuple[int, object]]]:
    with McapFile(path) as out:
        exporter = MapExporter(out, ExportSettings(scans=False))
        for stamp in (5_000_000_000, 6_000_000_000):
            exporter.frame(RegisteredFrame(stamp, np.empty((0, 3)), np.zeros(3),
                                           np.array([4.0, 3.0, 20.0]),
                                           np.array([0.0, 0.0, 0.0, 1.0])))
        exporter.finish(cast(Mapper, HandMap()), SHIFT, None)
    return read_back(path)[1]


def test_exported_grids_are_the_hand_drawn_map(tmp_path: Path) -> None:
    messages = _export(tmp_path / "hand.mcap")
    grid = messages["/alte/map/occupancy"]
    assert [t for t, _ in grid] == [5_000_000_000, 6_000_000_000]   # opening, then last
    occupancy = cast(object, grid[0][1])
    info = occupancy.info  # type: ignore[attr-defined]
    assert (info.width, info.height, info.resolution) == (8, 6, 1.0)
    # the grid's corner is the map's south-west corner in the world, one cell under it
    position = info.origin.position
    assert (position.x, position.y, position.z) == (100.0, 200.0, 2.0)
    values = np.asarray(occupancy.data, dtype=np.int8).reshape(6, 8)  # type: ignore[attr-defined]
    # the landing rule's 1.5 m half-side window reaches every cell it touches: 2 cells
    # either way; a cell whose window holds part of the block is occupied, the rest free
    rows, cols = np.indices((6, 8))
    near = np.maximum(np.maximum(2 - rows, rows - 3), np.maximum(4 - cols, cols - 5)) <= 2
    expected = np.where(near, 100, 0)
    expected[3, 7] = -1                                              # the unknown cell
    np.testing.assert_array_equal(values, expected)
    fox = cast(object, messages["/alte/map/grid"][0][1])
    assert (fox.column_count, fox.cell_stride, fox.row_stride) == (8, 9, 72)  # type: ignore[attr-defined]
    assert fox.pose.position.z == 1.5 and fox.frame_id == "map"  # type: ignore[attr-defined]
    raw = np.frombuffer(bytes(fox.data), np.uint8).reshape(6, 8, 9)  # type: ignore[attr-defined]
    elevation = raw[..., :4].copy().view("<f4")[..., 0]
    np.testing.assert_array_equal(elevation, HEIGHT.astype(np.float32))
    assert (raw[..., 4].view(np.int8) == values).all()
    alpha = raw[..., 8]
    assert alpha[3, 7] == 0 and (np.delete(alpha.ravel(), 3 * 8 + 7) == 255).all()
    # viridis: the lowest height its first colour (68, 1, 84), the highest its last
    assert tuple(raw[0, 0, 5:8]) == (68, 1, 84) and tuple(raw[2, 4, 5:8]) == (253, 231, 37)
    layers = cast(object, messages["/alte/map/grid_map"][0][1])
    elevation_layer = np.asarray(layers.data[0].data, np.float32)  # type: ignore[attr-defined]
    # grid_map: index (i, j) counts x and y cells from the north-east corner, stored
    # column-major (i fastest): element j * 8 + i
    np.testing.assert_array_equal(elevation_layer.reshape(6, 8), HEIGHT[::-1, ::-1])
    info = layers.info  # type: ignore[attr-defined]
    assert (info.length_x, info.length_y) == (8.0, 6.0)
    assert (info.pose.position.x, info.pose.position.y) == (104.0, 203.0)   # the centre
