"""MCAP exports of map runs, written with rosbags and read back with mcap + mcap_ros2."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory

from alte.errors import AlteError, ParameterError
from alte.export import TOPICS, ExportOptions, export_map, export_registered
from alte.export.maps import height_colours, shown_cells
from alte.io.reader import open_bag, topic_table
from alte.mappers import Feed
from alte.mappers.octomap import read_bt
from alte.pipeline import FrameSpec, MapSpec, open_input, prepare
from alte.sim import ensure_terrain

FRAMES = 8


@pytest.fixture(scope="module")
def terrains(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    root = tmp_path_factory.mktemp("terrains")
    return {n: ensure_terrain(n, root, frames=FRAMES) for n in ("sim_nav_1", "sim_lan_2")}


def read_back(path: Path) -> tuple[dict[str, tuple[str, str, int]], dict[str, list[Any]]]:
    """Schemas (name, encoding), counts and decoded messages per topic, with mcap_ros2."""
    with path.open("rb") as fh:
        reader = make_reader(fh, decoder_factories=[DecoderFactory()])
        summary = reader.get_summary()
        assert summary is not None and summary.statistics is not None
        table = {c.topic: (summary.schemas[c.schema_id].name,
                           summary.schemas[c.schema_id].encoding,
                           summary.statistics.channel_message_counts[c.id])
                 for c in summary.channels.values()}
        messages: dict[str, list[Any]] = {}
        for _, channel, message, decoded in reader.iter_decoded_messages():
            messages.setdefault(channel.topic, []).append((message.log_time, decoded))
    return table, messages


def test_octomap_run_on_sim_nav_1_reads_back(terrains: dict[str, Path], tmp_path: Path) -> None:
    target = tmp_path / "nav.mcap"
    result, counts = export_map(open_input(terrains["sim_nav_1"]), target,
                                MapSpec("octomap", {"resolution": 1.0}),
                                options=ExportOptions(timeline=4))
    table, messages = read_back(target)
    expected = {"/alte/scan": FRAMES, "/alte/pose": FRAMES, "/tf": FRAMES,
                "/alte/map/cells": 2, "/alte/map/octomap": 2, "/alte/trajectory": 2,
                "/alte/cloud": 1}
    assert {t: n for t, (_, _, n) in table.items()} == expected == counts
    assert all(table[t][:2] == (TOPICS[t], "ros2msg") for t in table)
    stamps = result.log.stamps
    assert [t for t, _ in messages["/alte/map/cells"]] == [stamps[3], stamps[7]]
    assert len(messages["/alte/trajectory"][-1][1].poses) == FRAMES
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
                           MapSpec("alte2d", {"max_res": 5}))
    table, messages = read_back(target)
    for topic in ("/alte/map/occupancy", "/alte/map/grid_map", "/alte/map/cells",
                  "/alte/cloud", "/alte/trajectory"):
        assert table[topic] == (TOPICS[topic], "ros2msg", 1)
    # By hand: max_res 5 splits the domain's square into at most 2^5 x 2^5 cells, so
    # the grid is 32 x 32 cells of size / 32, anchored at the domain's corner; sim_lan_2's
    # domain is the control volume's cube (scenario.json crop_box)
    crop = json.loads((terrains["sim_lan_2"] / "scenario.json").read_text())["crop_box"]
    size = max(hi - lo for lo, hi in zip(crop[:3], crop[3:], strict=True))
    occupancy = messages["/alte/map/occupancy"][0][1]
    assert occupancy.info.resolution == pytest.approx(size / 32, rel=1e-6)
    assert (occupancy.info.origin.position.x, occupancy.info.origin.position.y) == \
        pytest.approx((crop[0], crop[1]))
    assert (occupancy.info.width, occupancy.info.height) == (32, 32)
    gm = messages["/alte/map/grid_map"][0][1]
    assert gm.layers == ["elevation", "occupancy"]
    assert gm.info.resolution == pytest.approx(size / 32, rel=1e-6)
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
    result, counts = export_map(open_input(cloud), target, MapSpec("octomap", {"resolution": 1.0}),
                                FrameSpec(origin=(500_010.0, 5_400_010.0, 110.0)))
    assert counts["/tf_static"] == 1 and any(result.info.local_origin)
    _, messages = read_back(target)
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
    counts = export_registered(reg, target, options=ExportOptions(scans=False))
    assert counts == {"/alte/pose": FRAMES, "/tf": FRAMES, "/alte/trajectory": 1,
                      "/alte/cloud": 1}
    size = target.stat().st_size
    with pytest.raises(AlteError, match="already exists"):
        export_registered(reg, target)
    assert target.stat().st_size == size
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]
    with pytest.raises(ParameterError, match="--timeline 0"):
        ExportOptions(timeline=0)
    with pytest.raises(ParameterError, match="--feed frames"):
        export_map(reg, tmp_path / "q.mcap", MapSpec("quadtree", feed=Feed.BATCH),
                   options=ExportOptions(timeline=2))
    assert not (tmp_path / "q.mcap").exists()
