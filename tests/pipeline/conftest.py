"""A short simulated terrain folder and a plain bag of it, shared by the pipeline tests."""

from __future__ import annotations

from pathlib import Path

import pytest

from alte.sim.scenario import ensure_terrain


@pytest.fixture(scope="session")
def terrain(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """``sim_lan_1`` with 4 scans (bag, scenario.json, ground truth)."""
    return ensure_terrain("sim_lan_1", tmp_path_factory.mktemp("pipeline"), 0, 4)


@pytest.fixture(scope="session")
def bag(terrain: Path) -> Path:
    """The terrain's bag alone: no control volume, no voxel."""
    return terrain / "bag"
