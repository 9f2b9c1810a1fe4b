"""The pipeline's odometry step (alte.pipeline.posing): every scan posed, the selected kept."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np

from alte.io.bags.bag import evenly_spaced
from alte.pipeline import FrameSettings, PoseSource, StreamCounts, open_input, stream_frames


def test_odometry_reads_every_scan_and_registers_the_selected_ones(terrain: Path) -> None:
    """Odometry aligns consecutive scans, so with ``frames`` it still reads every scan and
    only the evenly spaced ones it selects go on, posed as in a run over all of them."""
    source = open_input(terrain / "bag")
    every, picked = StreamCounts(), StreamCounts()
    spec = FrameSettings(poses=PoseSource.ODOMETRY)
    full = list(stream_frames(source, source.resolve(spec), every))
    some = list(stream_frames(source, source.resolve(replace(spec, frames=2)), picked))
    assert (picked.scans, picked.selected, picked.read.frames, picked.poses.frames) == (4, 2, 4, 4)
    assert (every.selected, every.read.frames, len(full), len(some)) == (4, 4, 4, 2)
    assert sorted(evenly_spaced(4, 2) or ()) == [0, 3]
    assert [f.stamp for f in some] == [full[0].stamp, full[3].stamp]
    for mine, whole in zip(some, (full[0], full[3]), strict=True):
        np.testing.assert_allclose(mine.position, whole.position, atol=1e-9)
        np.testing.assert_allclose(mine.points, whole.points, atol=1e-9)
    assert "odometry over all 4 scans; 2 of them (evenly spaced) registered" in picked.notes
    assert not any("odometry over all" in n for n in every.notes)


def test_odometry_keeps_scans_as_taken_with_no_deskew(uav_first_scans: Path) -> None:
    """LIO deskews every timed scan and the frames carry it so; ``deskew=False``
    (``--no-deskew``) keeps the scans as taken for the odometry and the map alike (the
    mission's first 4 scans: consecutive, the IMU between them is 0.3 s to integrate)."""
    source = open_input(uav_first_scans / "bag")
    first = {}
    for deskew, deskewed in ((True, 4), (False, 0)):
        counts = StreamCounts()
        spec = FrameSettings(poses=PoseSource.ODOMETRY, deskew=deskew)
        frames = list(stream_frames(source, source.resolve(spec), counts))
        assert (counts.poses.method, counts.poses.deskewed, len(frames)) == ("lio", deskewed, 4)
        first[deskew] = frames[0]
    np.testing.assert_allclose(first[True].position, first[False].position)  # the anchor
    assert first[True].points.shape == first[False].points.shape
    assert np.abs(first[True].points - first[False].points).max() > 0.05
