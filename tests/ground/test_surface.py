"""The landing surface criterion: thresholds, ground references, synthetic and real terrain."""

from __future__ import annotations

import numpy as np
import pytest

from alte.errors import ParameterError
from alte.ground.surface import (
    OccupancySettings,
    classify_surface,
    local_ground,
    pixel_centres,
    plane_features,
)
from alte.io.points.pointfiles import read_points
from alte.paths import realdata_dir

STEP = 0.5


def xy(size: float = 60.0) -> tuple[np.ndarray, np.ndarray]:
    """Pixel-centre x, y grids of a ``size`` m square raster of STEP pixels."""
    centres = pixel_centres((0.0, 0.0), STEP, (int(size / STEP), int(size / STEP)))
    n = int(size / STEP)
    return centres[:, 0].reshape(n, n), centres[:, 1].reshape(n, n)


@pytest.mark.parametrize(("given", "match"), [
    ({"window": 0}, r"occupancy: window=0.0 out of range \(window > 0\)"),
    ({"max_slope_deg": 90}, r"max_slope_deg=90.0 out of range \(0 < max_slope_deg < 90\)"),
    ({"ground": "mesh"}, r"occupancy: ground='mesh' out of range \(plane\|local\|filter\)"),
    ({"ground_window": "wide"}, "ground_window='wide' is not a valid float"),
    ({"slope": 5}, r"occupancy: unknown parameter\(s\) slope; valid: ground, ground_window"),
])
def test_rule_is_validated(given: dict[str, object], match: str) -> None:
    with pytest.raises(ParameterError, match=match):
        OccupancySettings.parse(given)


def test_flat_ground_a_roof_and_a_hole() -> None:
    x, y = xy()
    height = np.full(x.shape, 2.0)
    roof = (np.abs(x - 20) < 6) & (np.abs(y - 20) < 6)  # 12 m wide, 3 m tall, flat top
    height[roof] = 5.0
    height[(np.abs(x - 45) < 1) & (np.abs(y - 45) < 1)] = np.nan
    for ground in ("plane", "local"):
        surface = classify_surface(height, (0.0, 0.0), STEP, OccupancySettings(ground=ground))
        occ = surface.occupancy()
        assert (occ[np.isnan(height)] == -1).all() and (occ[~np.isnan(height)] >= 0).all()
        assert surface.obstacle[roof].all() and (occ[roof] == 100).all()
        far = (np.hypot(x - 20, y - 20) > 12) & (np.hypot(x - 45, y - 45) > 3)
        assert (occ[far] == 0).all()


def test_the_local_ground_follows_a_hill_that_a_plane_cannot() -> None:
    """A smooth 3.5 m hill, nowhere steeper than 8.1 deg: all of it is landable by slope."""
    x, y = xy()
    height = 3.5 * np.exp(-((x - 30) ** 2 + (y - 30) ** 2) / (2 * 15.0**2))
    assert np.nanmax(plane_features(height, STEP, 1.5).slope_deg) < 10
    local = classify_surface(height, (0.0, 0.0), STEP)
    plane = classify_surface(height, (0.0, 0.0), STEP, OccupancySettings(ground="plane"))
    assert local.free.all()
    assert plane.obstacle.mean() > 0.3  # the hill's top half stands off any one plane
    box = height.copy()
    box[(np.abs(x - 30) < 2) & (np.abs(y - 30) < 2)] += 1.0  # a 1 m box on the hilltop
    assert classify_surface(box, (0.0, 0.0), STEP).occupancy()[60, 60] == 100


def test_the_filter_ground_follows_the_hill_and_flags_the_box() -> None:
    """The ground stage's SMRF on the raster: the hill is landable, a 1 m box on its top
    and a 3 m roof beside it are obstacles."""
    x, y = xy()
    height = 3.5 * np.exp(-((x - 30) ** 2 + (y - 30) ** 2) / (2 * 15.0**2))
    rule = OccupancySettings(ground="filter")
    assert classify_surface(height, (0.0, 0.0), STEP, rule).free.all()
    box = height.copy()
    box[(np.abs(x - 30) < 2) & (np.abs(y - 30) < 2)] += 1.0
    box[(np.abs(x - 10) < 4) & (np.abs(y - 45) < 3)] += 3.0
    surface = classify_surface(box, (0.0, 0.0), STEP, rule)
    assert surface.obstacle[60, 60] and surface.obstacle[90, 20]
    assert surface.obstacle.mean() < 0.05


def test_local_ground_ignores_unknown_pixels_and_the_outside() -> None:
    height = np.full((9, 9), 1.0)
    height[4, 4] = 3.0
    height[0, :] = np.nan
    ground = local_ground(height, 1.0, 3.0)
    assert ground[4, 4] == 1.0 and ground[8, 8] == 1.0 and ground[0, 0] == 1.0
    assert np.isnan(local_ground(np.full((3, 3), np.nan), 1.0, 3.0)).all()


REALDATA = realdata_dir() / "isprs_terrain"


def _rows(points: np.ndarray) -> np.ndarray:
    """One comparable value per float32 point (the files store x y z float32)."""
    return np.ascontiguousarray(points.astype(np.float32)).view(np.dtype((np.void, 12))).ravel()


@pytest.mark.realdata
@pytest.mark.slow
def test_local_ground_on_the_isprs_samples() -> None:
    """Airborne samples with reference bare earth: a plane calls half of the bare earth of
    samp21 (hilly) an obstacle; the local ground a few percent, and both leave the cells
    where most returns are not ground occupied."""
    from alte.export.grids import raster
    from alte.pipeline import MapSettings, open_input, run

    cloud = REALDATA / "samp21-utm.pcd"
    if not cloud.exists():
        pytest.skip(f"{cloud} absent")
    pts, ground = read_points(cloud), read_points(REALDATA / "samp21-utm-ground.pcd")
    is_ground = np.isin(_rows(pts), _rows(ground))
    grid = raster(run(open_input(cloud), MapSettings("alte2d", {"max_res": 7})).mapper.cells(),
                  np.zeros(3))
    ij = np.floor((pts[:, :2] - grid.origin) / grid.resolution).astype(int)
    flat = np.clip(ij[:, 1], 0, grid.shape[0] - 1) * grid.shape[1] + \
        np.clip(ij[:, 0], 0, grid.shape[1] - 1)
    count = np.bincount(flat, minlength=grid.height.size)
    other = (count - np.bincount(flat, is_ground, minlength=grid.height.size)).reshape(grid.shape)
    known = np.isfinite(grid.height)
    bare, objects = known & (count.reshape(grid.shape) > 0) & (other == 0), known & (
        other > count.reshape(grid.shape) / 2)
    assert bare.sum() > 5000 and objects.sum() > 1000
    local = classify_surface(grid.height, grid.origin, grid.resolution)
    plane = classify_surface(grid.height, grid.origin, grid.resolution,
                             OccupancySettings(ground="plane"))
    assert plane.obstacle[bare].mean() > 0.4 and local.obstacle[bare].mean() < 0.1
    assert local.occupied[objects].mean() > 0.97 and plane.occupied[objects].mean() > 0.97
    gentle = bare & (local.slope_deg <= 10)
    assert local.free[gentle].mean() > plane.free[gentle].mean() + 0.15
