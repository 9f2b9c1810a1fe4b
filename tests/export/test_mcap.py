"""The MCAP file writer: topics, latched QoS, atomic output."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from mcap.reader import make_reader

from alte.export.mcap import MAP_TOPICS, TOPICS, McapFile
from alte.export.rosmsg import blank, pose_stamped, tf_msg


def test_topics_and_latched_qos(tmp_path: Path) -> None:
    target = tmp_path / "out.mcap"
    with McapFile(target) as out:
        out.put("/alte/pose", 5, pose_stamped(5, "map", np.ones(3), np.array([0, 0, 0, 1.0])))
        out.put("/tf_static", 5, tf_msg(5, "map", "alte_local", np.zeros(3),
                                        np.array([0, 0, 0, 1.0])))
    assert out.counts == {"/alte/pose": 1, "/tf_static": 1}
    with target.open("rb") as fh:
        summary = make_reader(fh).get_summary()
    assert summary is not None
    qos = {c.topic: c.metadata["offered_qos_profiles"] for c in summary.channels.values()}
    assert "durability: transient_local" in qos["/tf_static"] and "depth: 1\n" in qos["/tf_static"]
    assert "durability: volatile" in qos["/alte/pose"]
    assert set(TOPICS) >= MAP_TOPICS


def test_an_interrupted_export_leaves_nothing(tmp_path: Path) -> None:
    target = tmp_path / "out.mcap"
    with pytest.raises(RuntimeError, match="stop"), McapFile(target) as out:
        out.put("/alte/map/octomap", 1, blank("octomap_msgs/msg/Octomap", id="OcTree"))
        raise RuntimeError("stop")
    assert list(tmp_path.iterdir()) == []


def test_opening_messages_come_first_and_the_file_is_in_log_time_order(tmp_path: Path) -> None:
    target = tmp_path / "out.mcap"
    quat = np.array([0, 0, 0, 1.0])
    with McapFile(target) as out:
        for stamp in (30, 10, 20):  # streamed out of order
            out.put("/alte/pose", stamp, pose_stamped(stamp, "map", np.zeros(3), quat))
        out.put("/tf_static", 10, tf_msg(10, "map", "alte_local", np.ones(3), quat),
                opening=True)
    with target.open("rb") as fh:
        reader = make_reader(fh)
        order = [(c.topic, m.log_time) for _, c, m in reader.iter_messages(log_time_order=False)]
        summary = reader.get_summary()
    assert order == [("/tf_static", 10), ("/alte/pose", 10), ("/alte/pose", 20),
                     ("/alte/pose", 30)]
    assert summary is not None and {c.compression for c in summary.chunk_indexes} == {"zstd"}
    assert out.counts == {"/alte/pose": 3, "/tf_static": 1}


def test_an_opening_message_after_the_start_is_refused(tmp_path: Path) -> None:
    target = tmp_path / "out.mcap"
    quat = np.array([0, 0, 0, 1.0])
    with pytest.raises(RuntimeError, match="opening message at 20 ns after the file's start"), \
            McapFile(target) as out:
        out.put("/alte/pose", 10, pose_stamped(10, "map", np.zeros(3), quat))
        out.put("/alte/pose", 20, pose_stamped(20, "map", np.zeros(3), quat), opening=True)
    assert list(tmp_path.iterdir()) == []
