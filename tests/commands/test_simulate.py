"""``alte simulate``: one terrain, all terrains, cache message, errors."""

import hashlib
import json
from collections import Counter
from pathlib import Path

from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory

from alte.cli import main
from alte.sim import TERRAINS


def read_mcap(path: Path) -> tuple[Counter, int, list[int]]:
    """With the mcap library's own ROS 2 decoder: messages per topic, the points of all
    clouds, and the clouds' header stamps (ns)."""
    topics: Counter = Counter()
    points, stamps = 0, []
    with path.open("rb") as fh:
        reader = make_reader(fh, decoder_factories=[DecoderFactory()])
        for _schema, channel, _message, ros in reader.iter_decoded_messages():
            topics[channel.topic] += 1
            if hasattr(ros, "point_step"):
                assert len(ros.data) == ros.width * ros.height * ros.point_step
                points += ros.width * ros.height
                stamps.append(ros.header.stamp.sec * 10**9 + ros.header.stamp.nanosec)
    return topics, points, stamps


def test_simulate_one_then_up_to_date(tmp_path, capsys):
    assert main(["simulate", "sim_lan_1", "--out", str(tmp_path), "--frames", "3"]) == 0
    out = capsys.readouterr().out
    assert "sim_lan_1: 3 frames" in out and "simulated in" in out
    assert main(["simulate", "sim_lan_1", "--out", str(tmp_path), "--frames", "3"]) == 0
    assert "up to date" in capsys.readouterr().out
    meta = json.loads((tmp_path / "sim_lan_1-3f" / "scenario.json").read_text())
    assert meta["storage"] == "sqlite3" and meta["frames_requested"] == 3


def test_simulate_all_with_mcap(tmp_path, capsys):
    assert main(["simulate", "all", "--out", str(tmp_path), "--frames", "2", "--seed", "5",
                 "--storage", "mcap"]) == 0
    out = capsys.readouterr().out
    for name in TERRAINS:
        assert f"{name}: 2 frames" in out
        folder = tmp_path / f"{name}-2f-s5"
        meta = json.loads((folder / "scenario.json").read_text())
        assert meta["seed"] == 5 and meta["storage"] == "mcap"
        mcap = folder / "bag" / "bag.mcap"
        assert meta["files"]["bag/bag.mcap"]["sha256"] == hashlib.sha256(
            mcap.read_bytes()).hexdigest()
        topics, points, stamps = read_mcap(mcap)
        counts = meta["counts"]
        assert topics[meta["cloud_topic"]] == counts["frames"] == 2
        assert topics[meta["pose_topic"]] == counts["poses"] >= 2
        assert points == counts["returns"] > 1000
        assert stamps == sorted(stamps) and len(set(stamps)) == 2


def test_unknown_terrain_is_a_one_line_error(tmp_path, capsys):
    assert main(["simulate", "moon", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert "unknown terrain 'moon'" in err and "exp_lan_2" in err


def test_bad_frames_is_an_error(tmp_path, capsys):
    assert main(["simulate", "sim_nav_1", "--out", str(tmp_path), "--frames", "0"]) == 2
    assert "frames=0" in capsys.readouterr().err
