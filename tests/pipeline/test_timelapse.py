"""Tests of the frame-by-frame time-lapse helper."""

from __future__ import annotations

import numpy as np
import pytest

from alte.errors import MapperError
from alte.mappers.alte2d import Alte2D
from alte.pipeline.timelapse import cube_domain, snapshot_indices, square_domain, timelapse


def sweep_frames(n: int = 6) -> list[tuple[np.ndarray, np.ndarray]]:
    rng = np.random.default_rng(0)
    frames = []
    for i in range(n):
        xy = rng.uniform(0, 4, (200, 2)) + np.array([2.0 * i, 0.0])
        z = np.where(xy[:, 0] > 6, 1.5, 0.0)
        frames.append((np.column_stack([xy, z]), np.array([2.0 * i + 2, 2.0, 10.0])))
    return frames


def test_timelapse_counts_and_snapshots() -> None:
    frames = sweep_frames()
    tl = timelapse(Alte2D(domain="0,0,16", kappa=0.01, max_res=4), frames,
                   times=np.arange(6) * 0.5, snapshots=3, progress=False)
    assert [s.frame for s in tl.snapshots] == [2, 3, 5]
    assert tl.snapshots[-1].frame == 5 and tl.snapshots[-1].time == 2.5
    batch = Alte2D(domain="0,0,16", kappa=0.01, max_res=4)
    batch.build(np.concatenate([p for p, _o in frames]))
    assert tl.basis_functions[-1] == batch.basis_functions
    assert len(tl.snapshots[-1].cells) == batch.basis_functions
    assert (np.diff(tl.basis_functions) >= 0).all() and tl.basis_functions[0] >= 1
    assert tl.points.sum() == 1200 and (tl.elapsed_s > 0).all()
    summary = tl.summary()
    assert summary["frames"] == 6 and summary["basis_functions"] == batch.basis_functions


def test_snapshot_indices_and_domain() -> None:
    assert snapshot_indices(10, 2).tolist() == [4, 9]
    assert snapshot_indices(3, 10).tolist() == [0, 1, 2]
    assert snapshot_indices(0, 3).tolist() == []
    assert square_domain(np.array([[-1.0, 2.0, 0.0], [5.0, 4.0, 3.0]])) == "-1.0,2.0,6.0"
    assert cube_domain(np.array([-1.0, 2.0, 0.0, 5.0, 4.0, 9.0])) == "-1.0,2.0,0.0,9.0"
    with pytest.raises(MapperError, match="no extent"):
        cube_domain(np.ones(6))
    with pytest.raises(MapperError, match="snapshots=0"):
        snapshot_indices(5, 0)
    with pytest.raises(MapperError, match="no x/y extent"):
        square_domain(np.zeros(6))
    with pytest.raises(MapperError, match="2 times for 6 frames"):
        timelapse(Alte2D(), sweep_frames(), times=[0.0, 1.0], progress=False)
