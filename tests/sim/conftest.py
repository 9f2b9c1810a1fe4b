"""Small simulated terrains shared by the simulator tests (generated once per session)."""

import pytest

from alte.sim import ensure_terrain

SMALL = 40


@pytest.fixture(scope="session")
def small_data(tmp_path_factory):
    """Folder holding every terrain with ``SMALL`` evenly spaced scans."""
    return tmp_path_factory.mktemp("simdata")


@pytest.fixture(scope="session")
def small_terrain(small_data):
    """``name -> folder`` of the small simulation of that terrain (made on first use)."""
    def make(name, frames=SMALL):
        return ensure_terrain(name, small_data / f"f{frames}", seed=0, frames=frames)
    return make
