"""Tests for ``alte export`` and the ``--mcap`` flags of ``alte map`` and ``alte register``."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from mcap.reader import make_reader
from support.mcapfiles import container, read_back
from support.synthetic import scene

from alte.cli import main
from alte.io import write_frames
from alte.sim import ensure_terrain


@pytest.fixture
def bag(tmp_path: Path) -> Path:
    _, frames, mount = scene(seed=2, frames=6, n=400)
    return write_frames(tmp_path / "scans", frames, mount)


def topics(path: Path) -> dict[str, int]:
    with path.open("rb") as fh:
        summary = make_reader(fh).get_summary()
    assert summary is not None and summary.statistics is not None
    return {c.topic: summary.statistics.channel_message_counts[c.id]
            for c in summary.channels.values()}


def test_export_writes_the_mcap_with_a_timeline(bag: Path, tmp_path: Path, capsys) -> None:
    target = tmp_path / "run.mcap"
    argv = ["export", str(bag), "--mcap", str(target), "--mapper", "quadtree",
            "--set", "max_points=20", "--timeline", "2", "--json"]
    assert main(argv) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["feed"] == "frames"  # quadtree's batch build switched to frames for a timeline
    assert out["mcap"]["messages"] == topics(target)
    # the final map at the first instant, then scans 2, 4 and 6
    assert topics(target)["/alte/map/occupancy"] == 4 and topics(target)["/alte/scan"] == 6
    assert main(argv) == 2
    assert "already exists" in capsys.readouterr().err


@pytest.mark.parametrize(("extra", "message"), [
    (["--mcap", "run.bag"], "--mcap run.bag: the file name must end in .mcap"),
    (["--mcap", "run.mcap", "--timeline", "0"],
     "--timeline: export: timeline=0 out of range (timeline >= 1)"),
    (["--mcap", "run.mcap", "--timeline", "2", "--feed", "batch"],
     "--timeline 2 with --feed batch: export: a timeline needs feed=frames (a batch build "
     "has no map before the last scan); use --feed frames"),
    (["--mcap", "run.mcap", "--occupancy-set", "max_slope_deg=95"],
     r"--occupancy-set: occupancy: max_slope_deg=95.0 out of range (0 < max_slope_deg < 90)"),
    (["--mcap", "run.mcap", "--occupancy-set", "slope=5"],
     "--occupancy-set: occupancy: unknown parameter(s) slope; valid: ground, ground_window"),
    (["--mcap", "run.mcap", "--occupancy-set", "ground"],
     "--occupancy-set: --occupancy-set 'ground': expected KEY=VALUE"),
])
def test_export_refuses_bad_flags(bag: Path, tmp_path: Path, capsys, extra, message) -> None:
    argv = ["export", str(bag), "--mapper", "quadtree", *extra]
    argv = [str(tmp_path / a) if a.startswith("run.") else a for a in argv]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and message.replace("run.", str(tmp_path / "run.")) in err
    assert not list(tmp_path.glob("run.*"))


def test_map_and_register_write_mcap_too(bag: Path, tmp_path: Path, capsys) -> None:
    target = tmp_path / "map.mcap"
    assert main(["map", str(bag), "--mapper", "alte3d", "--mcap", str(target), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["mcap"]["messages"]["/alte/map/cells"] == 2  # at the start and the end
    assert main(["map", str(bag), "--mapper", "alte3d", "--timeline", "2"]) == 2
    assert "--timeline shapes the map written into --mcap FILE; add it" in \
        capsys.readouterr().err
    assert main(["map", str(bag), "--mapper", "alte3d", "--occupancy-set", "window=2"]) == 2
    assert "--occupancy-set shapes the map written into --mcap FILE" in capsys.readouterr().err
    reg = tmp_path / "reg.mcap"
    assert main(["register", str(bag), "--out", str(tmp_path / "c.npz"), "--mcap", str(reg)]) == 0
    assert "messages to" in capsys.readouterr().out
    assert topics(reg) == {"/alte/scan": 6, "/alte/pose": 6, "/tf": 6, "/alte/trajectory": 2,
                           "/alte/cloud": 2}
    assert np.load(tmp_path / "c.npz")["points"].shape[1] == 3


def test_map_of_a_landing_terrain_opens_on_the_final_map(tmp_path: Path, capsys) -> None:
    """``alte map TERRAIN --mapper alte2d --mcap F``: map, occupancy and Foxglove grid at the
    file's start time, free and occupied cells, -1 only where unseen, zstd chunks; read
    back by rosbags (container, CRCs) and decoded by mcap_ros2."""
    terrain = ensure_terrain("sim_lan_2", tmp_path / "data", frames=8)
    target = tmp_path / "F.mcap"
    assert main(["map", str(terrain), "--mapper", "alte2d", "--mcap", str(target),
                 "--occupancy-set", "max_slope_deg=12", "--json"]) == 0
    capsys.readouterr()
    table, messages = read_back(target)
    start = min(stamp for topic in messages for stamp, _ in messages[topic])
    for topic in ("/alte/map/cells", "/alte/map/occupancy", "/alte/map/grid",
                  "/alte/map/grid_map", "/alte/trajectory", "/alte/cloud"):
        assert messages[topic][0][0] == start
    assert table["/alte/map/grid"][0] == "foxglove_msgs/msg/Grid"
    grid = messages["/alte/map/occupancy"][0][1]
    values = np.asarray(grid.data)
    heights = np.frombuffer(bytes(messages["/alte/map/grid"][0][1].data), dtype=np.uint8)
    elevation = heights.reshape(-1, 9)[:, :4].copy().view("<f4").ravel()
    assert (values == 0).any() and (values == 100).any()
    assert ((values == -1) == np.isnan(elevation)).all()
    compressions, chunk_crcs, data_crc = container(target)
    assert compressions == {"zstd"} and chunk_crcs and data_crc != 0
