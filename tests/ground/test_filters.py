"""The ground filters: a synthetic slope with boxes and trees (ground known), the published
defaults pinned, bad input refused with typed errors."""

from __future__ import annotations

import numpy as np
import pytest

from alte.errors import GroundError, ParameterError
from alte.ground.filters import filter_ground, looks_gridded
from alte.ground.obstacles import find_obstacles
from alte.ground.settings import (
    DEFAULT_METHOD,
    DEFAULT_SETTINGS,
    METHODS,
    CsfSettings,
    MorphSettings,
    PlaneSettings,
    SmrfSettings,
    ground_settings,
)
from alte.lab.studies.realdata.ground import ground_errors

UTM = np.array([513_000.0, 5_404_000.0, 0.0])


def slope_with_objects(seed: int = 0, size: float = 60.0) -> tuple[np.ndarray, np.ndarray]:
    """A 10 % slope (with a gentle hump) at ~2 points/m^2, two box buildings (6 m, 4 m)
    and a grove of trees (canopy 3-9 m over trunks); the mask says which points are ground."""
    rng = np.random.default_rng(seed)
    n = int(2 * size * size)
    xy = rng.uniform(0, size, (n, 2))

    def terrain(p: np.ndarray) -> np.ndarray:
        return 100 + 0.10 * p[:, 0] + 0.03 * p[:, 1] + 1.5 * np.exp(
            -((p[:, 0] - 40) ** 2 + (p[:, 1] - 15) ** 2) / 200)

    z = terrain(xy) + rng.normal(0, 0.03, n)
    box1 = (np.abs(xy[:, 0] - 15) < 6) & (np.abs(xy[:, 1] - 40) < 5)
    box2 = (np.abs(xy[:, 0] - 45) < 3) & (np.abs(xy[:, 1] - 45) < 4)
    z[box1] += 6.0
    z[box2] += 4.0
    grove = np.hypot(xy[:, 0] - 20, xy[:, 1] - 12) < 7
    canopy = grove & (rng.random(n) < 0.7)  # 30 % of the returns reach the ground
    z[canopy] += rng.uniform(3, 9, int(canopy.sum()))
    return np.column_stack([xy, z]), ~(box1 | box2 | canopy)


@pytest.fixture(scope="module")
def scene() -> tuple[np.ndarray, np.ndarray]:
    return slope_with_objects()


def kappa(pred: np.ndarray, ref: np.ndarray) -> float:
    return ground_errors(pred, ref)["kappa_pct"]


@pytest.mark.parametrize(("method", "floor"), [("smrf", 95.0), ("csf", 80.0),
                                               ("morph", 80.0)])
def test_filters_find_the_known_ground(scene: tuple[np.ndarray, np.ndarray], method: str,
                                       floor: float) -> None:
    points, truth = scene
    result = filter_ground(points + UTM, method)  # georeferenced input is handled
    assert result.ground.shape == truth.shape and result.method == method
    assert kappa(result.ground, truth) >= floor
    assert result.cpu_s >= 0 and 0.5 < result.share < 0.95
    if result.height is not None:
        # the bare earth under the buildings is the slope, not the roofs
        roof = (np.abs(points[:, 0] - 15) < 4) & (np.abs(points[:, 1] - 40) < 3)
        below = (result.height - UTM[2])[roof] - points[roof, 2]
        assert np.median(below) < -4.5


def test_the_plane_misses_the_hump_a_local_filter_follows(
        scene: tuple[np.ndarray, np.ndarray]) -> None:
    points, truth = scene
    plane, smrf = filter_ground(points, "plane"), filter_ground(points, "smrf")
    assert kappa(smrf.ground, truth) > kappa(plane.ground, truth) + 10


def test_the_same_filter_judges_other_heights(scene: tuple[np.ndarray, np.ndarray]) -> None:
    points, truth = scene
    result = filter_ground(points, "smrf")
    np.testing.assert_array_equal(result.classify(points[:, 2]) , result.ground)
    lifted = result.classify(points[:, 2] + 5.0)
    assert not lifted[truth].any()
    with pytest.raises(ParameterError, match="csf: the method gives no bare-earth surface"):
        filter_ground(points, "csf").classify(points[:, 2])


def test_published_defaults_are_pinned() -> None:
    assert SmrfSettings().as_dict() == {"cell": 1.0, "window": 18.0, "slope": 0.15,
                                        "threshold": 0.5, "scalar": 1.25}
    assert CsfSettings().as_dict() == {"resolution": 1.0, "rigidness": 3, "slope_smooth": True,
                                       "threshold": 0.5, "iterations": 500, "time_step": 0.65}
    assert MorphSettings().as_dict() == {"step": 1.0, "window": 20.0, "tolerance": 1.0}
    assert PlaneSettings().as_dict() == {"fit_threshold": 0.1, "tolerance": 0.3,
                                         "max_angle_deg": 30.0, "seed": 0}
    import CSF

    package = CSF.CSF().params  # the CSF package's own defaults are ours
    assert (package.cloth_resolution, package.rigidness, package.bSloopSmooth,
            package.class_threshold, package.interations) == (1.0, 3, True, 0.5, 500)
    assert package.time_step == pytest.approx(0.65)
    assert DEFAULT_METHOD in METHODS and isinstance(DEFAULT_SETTINGS, METHODS[DEFAULT_METHOD])
    assert ground_settings() == DEFAULT_SETTINGS  # the stage's choice on real data
    assert ground_settings("smrf") == SmrfSettings()  # a named method: its publication's
    assert SmrfSettings(slope=0.10) == DEFAULT_SETTINGS


@pytest.mark.parametrize(("method", "given", "match"), [
    ("smrf", {"slope": "-1"}, r"ground smrf: slope=-1.0 out of range \(slope >= 0\)"),
    ("csf", {"rigidness": 4}, r"ground csf: rigidness=4 out of range \(rigidness 1, 2 or 3\)"),
    ("smrf", {"windw": 3}, r"ground smrf: unknown parameter\(s\) windw; valid: cell, "),
    ("tin", {}, r"ground: method='tin' unknown; valid: smrf, csf, morph, plane"),
])
def test_settings_are_validated(method: str, given: dict[str, object], match: str) -> None:
    with pytest.raises(ParameterError, match=match):
        ground_settings(method, given)


def test_bad_clouds_are_refused() -> None:
    with pytest.raises(GroundError, match="ground smrf: 0 point"):
        filter_ground(np.empty((0, 3)))
    with pytest.raises(GroundError, match="ground smrf: 2 point"):
        filter_ground(np.zeros((2, 3)))
    with pytest.raises(ParameterError, match="NaN or inf"):
        filter_ground(np.array([[0.0, 0, 0], [1, 0, np.nan], [0, 1, 0]]))
    with pytest.raises(ParameterError, match=r"shape \(N, 3\)"):
        filter_ground(np.zeros((5, 2)))
    with pytest.raises(ParameterError, match="settings are MorphSettings, not SmrfSettings"):
        filter_ground(np.zeros((5, 3)), "smrf", MorphSettings())


def test_a_dem_given_as_points_is_named() -> None:
    gx, gy = np.meshgrid(np.arange(50.0) * 2 + 500_000, np.arange(40.0) * 2 + 5e6)
    dem = np.column_stack([gx.ravel(), gy.ravel(), 100 + 0.1 * gx.ravel() % 7])
    assert looks_gridded(dem) == pytest.approx(2.0)
    with pytest.raises(GroundError, match="regular 2 m grid, one point per cell: a raster DEM"):
        filter_ground(dem)
    holes = dem[np.random.default_rng(0).random(len(dem)) < 0.7]  # voids stay a grid
    assert looks_gridded(holes) == pytest.approx(2.0)
    points, _ = slope_with_objects(size=20.0)
    assert looks_gridded(points) is None
    assert looks_gridded(np.round(points, 1)) is None  # quantised LiDAR is not a DEM


def test_obstacles_stand_on_the_bare_earth(scene: tuple[np.ndarray, np.ndarray]) -> None:
    """The boxes are obstacles of their own height above the slope; the hump is not one,
    though it rises 1.5 m above a plane through the site."""
    points, truth = scene
    found = find_obstacles(points, tolerance=1.5, min_size=20)  # ~2 points/m^2
    table = found.table
    boxes = [(15.0, 40.0, 6.0), (45.0, 45.0, 4.0)]
    for x, y, height in boxes:
        near = np.hypot(table["x"] - x, table["y"] - y) < 3
        assert near.sum() == 1, table
        assert table.loc[near, "height"].iloc[0] == pytest.approx(height, abs=0.5)
    obstacle = found.labels >= 0
    hump = np.hypot(points[:, 0] - 40, points[:, 1] - 15) < 5
    assert not (obstacle & hump & truth).any()
    assert not (obstacle & truth).mean() > 0.01
    with pytest.raises(ParameterError, match="ground csf gives no bare earth"):
        find_obstacles(points, filter_ground(points, "csf"))
    with pytest.raises(ParameterError, match="min_height=-1"):
        find_obstacles(points, min_height=-1)
