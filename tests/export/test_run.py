"""MCAP exports of map runs: serialised by rosbags, written by mcap, read back by rosbags'
MCAP reader (container, CRCs) and decoded by mcap_ros2 (an independent CDR decoder)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from support.mcapfiles import container, read_back

from alte.errors import AlteError, ParameterError
from alte.export import TOPICS, ExportSettings, export_map, export_registered
from alte.export.grids import height_colours, raster
from alte.export.maps import shown_cells
from alte.io.bags.reader import open_bag, topic_table
from alte.mappers import Feed
from alte.mappers.octomap import read_bt
from alte.pipeline import FrameSettings, MapSettings, open_input, prepare
from alte.sim import ensure_terrain

FRAMES = 8


@pytest.fixture(scope="module")
def terrains(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    root = tmp_path_factory.mktemp("terrains")
    return {n: ensure_terrain(n, root, frames=FRAMES) for n in ("sim_nav_1", "sim_lan_2")}


def test_octomap_run_on_sim_nav_1_reads_back(terrains: dict[str, Path], tmp_path: Path) -> None:
    target = tmp_path / "nav.mcap"
    result, counts = export_map(open_input(terrains["sim_nav_1"]), target,
                                MapSettings("octomap", {"resolution": 1.0}),
                                options=ExportSettings(timeline=4))
    table, messages = read_back(target)
    expected = {"/alte/scan": FRAMES, "/alte/pose": FRAMES, "/tf": FRAMES,
                "/alte/map/cells": 3, "/alte/map/octomap": 3, "/alte/map/occupancy": 3,
                "/alte/map/grid": 3, "/alte/trajectory": 3, "/alte/cloud": 2}
    assert {t: n for t, (_, _, n) in table.items()} == expected == counts
    assert all(table[t][:2] == (TOPICS[t], "ros2msg") for t in table)
    stamps = result.log.stamps
    # the final map at the first instant, then the timeline's growth (scans 4 and 8)
    assert [t for t, _ in messages["/alte/map/cells"]] == [stamps[0], stamps[3], stamps[7]]
    assert [len(m.poses) for _, m in messages["/alte/trajectory"]] == [FRAMES, 4, FRAMES]
    first, last = (messages["/alte/map/cells"][k][1].markers for k in (0, -1))
    assert [len(m.points) for m in first] == [len(m.points) for m in last]
    assert first[1].header.stamp.sec * 10**9 + first[1].header.stamp.nanosec == stamps[0]
    occupancy = messages["/alte/map/occupancy"][0][1].data
    assert {0, 100} <= set(np.unique(occupancy)) <= {-1, 0, 100}  # from the top surface
    cells = result.mapper.cells()
    occupied = cells.centers[cells.occupied]
    markers = messages["/alte/map/cells"][-1][1].markers
    drawn = [(p, c) for m in markers[1:] for p, c in zip(m.points, m.colors, strict=True)]
    assert len(drawn) == len(occupied)
    colours = height_colours(occupied[:, 2])
    k = int(np.argmax(occupied[:, 2]))
    colour = next(c for p, c in drawn if (p.x, p.y, p.z) == tuple(occupied[k]))
    assert np.allclose([colour.r, colour.g, colour.b, colour.a], colours[k])
    octo = messages["/alte/map/octomap"][-1][1]
    assert octo.header.frame_id == "map" and octo.resolution == 1.0 and octo.binary
    bt = tmp_path / "back.bt"
    result.mapper.write_bt(bt)
    body = bt.read_bytes()
    assert body.endswith(bytes(np.asarray(octo.data, dtype=np.int8).tobytes()))
    assert read_bt(bt).occupied.sum() > 0


def test_alte2d_run_on_sim_lan_2_reads_back(terrains: dict[str, Path], tmp_path: Path) -> None:
    target = tmp_path / "lan.mcap"
    result, _ = export_map(open_input(terrains["sim_lan_2"]), target,
                           MapSettings("alte2d", {"max_res": 5}))
    table, messages = read_back(target)
    start = min(stamp for topic in messages for stamp, _ in messages[topic])
    assert start == result.log.stamps[0]
    for topic in ("/alte/map/occupancy", "/alte/map/grid", "/alte/map/grid_map",
                  "/alte/map/cells", "/alte/cloud", "/alte/trajectory"):
        assert table[topic] == (TOPICS[topic], "ros2msg", 2)  # at the start and at the end
        assert [t for t, _ in messages[topic]] == [start, result.log.stamps[-1]]
    compressions, chunk_crcs, data_crc = container(target)
    assert compressions == {"zstd"} and chunk_crcs and data_crc != 0
    grid = raster(result.mapper.cells(), np.zeros(3))
    occupancy = messages["/alte/map/occupancy"][0][1]
    values = np.asarray(occupancy.data).reshape(grid.shape)
    assert (values == grid.occupancy).all()
    assert (values == 0).sum() > 0.5 * values.size and (values == 100).any()
    assert ((values == -1) == ~np.isfinite(grid.height)).all()  # -1 only where unseen
    assert occupancy.info.origin.position.z < np.nanmin(grid.height)  # under the map
    fox = messages["/alte/map/grid"][0][1]
    assert [f.name for f in fox.fields][:2] == ["elevation", "occupancy"]
    assert (fox.column_count, len(fox.data)) == (grid.shape[1], grid.height.size * 9)
    packed = np.frombuffer(bytes(fox.data), dtype=np.uint8).reshape(*grid.shape, 9)
    assert (packed[..., 4].view(np.int8) == values).all()
    assert occupancy.info.resolution == pytest.approx(grid.resolution)
    assert (occupancy.info.origin.position.x, occupancy.info.origin.position.y) == \
        pytest.approx(tuple(grid.origin))
    assert (occupancy.info.width, occupancy.info.height) == grid.shape[::-1]
    domain = result.mapper.domain
    assert domain is not None and grid.resolution == pytest.approx(domain.size / 2 ** 5)
    gm = messages["/alte/map/grid_map"][0][1]
    assert gm.layers == ["elevation", "occupancy"]
    assert gm.info.resolution == pytest.approx(grid.resolution)
    cloud = messages["/alte/cloud"][0][1]
    assert cloud.width == len(result.cloud) and cloud.header.frame_id == "map"
    cells = result.mapper.cells()
    assert sum(len(m.points) for m in messages["/alte/map/cells"][0][1].markers) == \
        int(shown_cells(cells, 2).sum())


def test_shifted_map_gets_a_local_frame_and_alte_reads_its_own_file(tmp_path: Path) -> None:
    rng = np.random.default_rng(0)
    points = rng.uniform(0, 20, (3000, 3)) * [1, 1, 0.1] + [500_000.0, 5_400_000.0, 100.0]
    cloud = tmp_path / "utm.npz"
    np.savez(cloud, points=points)
    target = tmp_path / "utm.mcap"
    result, counts = export_map(open_input(cloud), target,
                                MapSettings("octomap", {"resolution": 1.0}),
                                FrameSettings(origin=(500_010.0, 5_400_010.0, 110.0)))
    assert counts["/tf_static"] == 1 and any(result.info.local_origin)
    _, messages = read_back(target)
    assert messages["/tf_static"][0][0] == messages["/alte/pose"][0][0]  # at the start
    tf = messages["/tf_static"][0][1].transforms[0]
    assert (tf.header.frame_id, tf.child_frame_id) == ("map", "alte_local")
    assert tf.transform.translation.x == result.info.local_origin[0]
    assert messages["/alte/map/octomap"][0][1].header.frame_id == "alte_local"
    marker = messages["/alte/map/cells"][0][1].markers[1]
    assert marker.points[0].x > 499_000  # cubes in the map frame
    with open_bag(target) as reader:  # rosbags: alte's own reader opens the export
        assert set(topic_table(reader)) == set(counts)


def test_registration_export_and_refusals(terrains: dict[str, Path], tmp_path: Path) -> None:
    reg = prepare(open_input(terrains["sim_lan_2"]))
    target = tmp_path / "reg.mcap"
    counts = export_registered(reg, target, options=ExportSettings(scans=False))
    assert counts == {"/alte/pose": FRAMES, "/tf": FRAMES, "/alte/trajectory": 2,
                      "/alte/cloud": 2}
    size = target.stat().st_size
    with pytest.raises(AlteError, match="already exists"):
        export_registered(reg, target)
    assert target.stat().st_size == size
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]
    with pytest.raises(ParameterError, match=r"export: timeline=0 out of range \(timeline >= 1\)"):
        ExportSettings(timeline=0)
    with pytest.raises(ParameterError, match="export: a timeline needs feed=frames"):
        export_map(reg, tmp_path / "q.mcap", MapSettings("quadtree", feed=Feed.BATCH),
                   options=ExportSettings(timeline=2))
    assert not (tmp_path / "q.mcap").exists()
