"""The elevation map as an alte mapper: the contract, the registry, the noise model, cells."""

import numpy as np
import pytest
from alte_elevation import ElevationMap, point_variance

from alte.errors import ParameterError
from alte.mappers import VARIANCE, registry
from alte.mappers.api import Domain
from alte.pipeline import MapSettings
from alte.testing import check_mapper, scene


def test_meets_the_contract() -> None:
    check_mapper(ElevationMap)


def test_found_by_its_entry_point() -> None:
    """Installed, the package's entry point makes it a mapper of the registry."""
    assert registry.resolve("elevation") is ElevationMap
    assert MapSettings("elevation", {"resolution": "0.25"}).record.resolution == 0.25
    with pytest.raises(ParameterError, match=r"elevation: resolution=0\.0 out of range"):
        MapSettings("elevation", {"resolution": 0})


def test_point_variance_by_range_and_angle() -> None:
    """Straight down: the range noise; horizontal at 10 m: (c + a d)^2; at 45 degrees the
    mean of both; without an origin the range noise."""
    pts = np.array([[0.0, 0.0, 0.0], [10.0, 0.0, 10.0], [10.0, 0.0, 0.0]])
    origin = np.tile([0.0, 0.0, 10.0], (3, 1))
    var = point_variance(pts, origin, 0.03, 0.0015, 0.0006)
    lateral = lambda d: (0.0015 + 0.0006 * d) ** 2  # noqa: E731
    assert var[0] == pytest.approx(0.03**2)
    assert var[1] == pytest.approx(lateral(10.0))
    assert var[2] == pytest.approx(0.5 * 0.03**2 + 0.5 * lateral(np.sqrt(200.0)))
    assert point_variance(pts, None, 0.03, 0.0015, 0.0006).tolist() == [0.03**2] * 3


def test_cells_and_layers() -> None:
    """On the conformance scene: cells on the grid of the domain, heights of the ground
    and the block, layers consistent, sigma under the point noise where many points fell."""
    mapper = ElevationMap(Domain(0.0, 0.0, -2.0, 20.0), resolution=1.0)
    for points, origin in scene():
        mapper.insert(points, origin)
    cells = mapper.cells()
    assert set(cells.layers) == {VARIANCE, "min", "max", "count"}
    assert np.allclose((cells.centers[:, :2] - 0.5) % 1.0, 0.0)
    assert cells.layers["count"].sum() == 3000
    assert np.all(cells.layers["min"] <= cells.layers["max"])
    block = (np.abs(cells.centers[:, 0] - 9.0) < 0.6) & (np.abs(cells.centers[:, 1] - 7.0) < 0.6)
    assert np.allclose(cells.centers[block, 2], 1.5, atol=0.02)
    ground = cells.layers["max"] < 0.1
    assert np.allclose(cells.centers[ground, 2], 0.0, atol=0.02)
    sigma = np.sqrt(cells.layers[VARIANCE][ground])
    assert np.median(sigma) < 0.03


def test_view_parameters_reread_the_stored_map() -> None:
    mapper = ElevationMap(resolution=1.0)
    for points, origin in scene():
        mapper.insert(points, origin)
    strict = mapper.reread(max_variance=1e-5)
    assert np.isnan(strict.cells().centers[:, 2]).sum() > np.isnan(
        mapper.cells().centers[:, 2]).sum()
    narrow = mapper.reread(spread=False)
    assert np.nanmax(narrow.cells().layers[VARIANCE]) <= np.nanmax(
        mapper.cells().layers[VARIANCE])


def test_the_first_name_of_the_settings_record_still_imports() -> None:
    import alte_elevation

    with pytest.warns(DeprecationWarning, match="use ElevationSettings"):
        old = alte_elevation.ElevationParams
    assert old is alte_elevation.ElevationSettings
