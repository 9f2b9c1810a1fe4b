"""Tests for ``alte export`` and the ``--mcap`` flags of ``alte map`` and ``alte register``."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from mcap.reader import make_reader
from support.synthetic import scene

from alte.cli import main
from alte.io import write_frames


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
    assert topics(target)["/alte/map/occupancy"] == 3 and topics(target)["/alte/scan"] == 6
    assert main(argv) == 2
    assert "already exists" in capsys.readouterr().err


@pytest.mark.parametrize(("extra", "message"), [
    (["--mcap", "run.bag"], "--mcap run.bag: the file name must end in .mcap"),
    (["--mcap", "run.mcap", "--timeline", "0"], "--timeline 0: expected a positive number"),
    (["--mcap", "run.mcap", "--timeline", "2", "--feed", "batch"], "use --feed frames"),
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
    assert summary["mcap"]["messages"]["/alte/map/cells"] == 1
    assert main(["map", str(bag), "--mapper", "alte3d", "--timeline", "2"]) == 2
    assert "--timeline writes the growing map into --mcap FILE" in capsys.readouterr().err
    reg = tmp_path / "reg.mcap"
    assert main(["register", str(bag), "--out", str(tmp_path / "c.npz"), "--mcap", str(reg)]) == 0
    assert "messages to" in capsys.readouterr().out
    assert topics(reg) == {"/alte/scan": 6, "/alte/pose": 6, "/tf": 6, "/alte/trajectory": 1,
                           "/alte/cloud": 1}
    assert np.load(tmp_path / "c.npz")["points"].shape[1] == 3
