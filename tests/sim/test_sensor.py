"""VLP-16 model: beam geometry, ray casting and the range noise model."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from alte.sim.scene import SceneBuilder
from alte.sim.sensor import FIRING_ORDER_DEG, VLP16, cast, measure


def test_beam_elevations_follow_the_firing_order():
    az, el, laser = VLP16().beams()
    assert np.array_equal(el[:16], [-15, 1, -13, 3, -11, 5, -9, 7, -7, 9, -5, 11, -3, 13, -1, 15])
    assert np.array_equal(np.sort(FIRING_ORDER_DEG), np.arange(-15, 16, 2))
    assert np.array_equal(laser[:16], np.arange(16))
    assert np.all(az[:16] == az[0])


def test_azimuth_step_and_field_of_view():
    sensor = VLP16()
    az = sensor.azimuths_deg()
    assert len(az) == 450 and sensor.directions().shape == (7200, 3)
    assert np.allclose(np.diff(az), 0.2)
    assert az.min() == pytest.approx(-45.0) and az.max() < 45.0
    assert sensor.rate_hz == 10.0


def test_directions_use_the_manual_convention():
    d = VLP16(fov_half_deg=90.0, azimuth_step_deg=90.0).directions()
    az, el, _ = VLP16(fov_half_deg=90.0, azimuth_step_deg=90.0).beams()
    level = el == -1  # nearly horizontal beam
    # azimuth 0 -> +y, azimuth -90 -> -x (clockwise from +y)
    assert np.allclose(d[level & (az == 0)][0], [0, np.cos(np.radians(1)), -np.sin(np.radians(1))])
    assert d[level & (az == -90)][0][0] < -0.99
    assert np.allclose(np.linalg.norm(d, axis=1), 1.0)


def _floor_hits(k=4, height=10.0):
    b = SceneBuilder()
    b.ground("g", (-500, -500, 500, 500))
    scene = b.build()
    down = Rotation.from_euler("x", np.full((k, 1), -60.0), degrees=True)  # sensor +y tilted down
    return cast(scene.raycaster(), np.tile([0.0, 0.0, height], (k, 1)), down, VLP16().directions())


def test_cast_hits_the_floor_at_the_geometric_range():
    hits = _floor_hits()
    d = VLP16().directions()
    world = Rotation.from_euler("x", -60.0, degrees=True).apply(d)
    expected = 10.0 / -world[:, 2]
    assert np.allclose(hits.distance[0], expected, rtol=1e-5)
    assert np.allclose(hits.cos_incidence[0], -world[:, 2], atol=1e-5)
    assert np.all(hits.triangle >= 0)


def test_noise_is_gaussian_with_the_data_sheet_sigma_and_truncated():
    hits = _floor_hits(k=20)
    sensor = VLP16()
    ranges, counts = measure(hits, sensor, [np.random.default_rng(i) for i in range(20)])
    err = ranges - hits.distance
    assert counts["returns"] == 20 * 7200
    assert np.std(err) == pytest.approx(0.03, rel=0.05)
    assert np.abs(err).max() <= 4 * 0.03 + 1e-12


def test_no_return_beyond_range_or_at_grazing_incidence():
    hits = _floor_hits(k=1, height=10.0)
    ranges, counts = measure(hits, VLP16(max_range=15.0), [np.random.default_rng(0)])
    assert counts["out_of_range"] == int((hits.distance > 15.0).sum()) > 0
    assert np.all(np.isnan(ranges[hits.distance > 15.0]))
    ranges, counts = measure(hits, VLP16(max_incidence_deg=40.0), [np.random.default_rng(0)])
    assert counts["grazing"] == int((hits.cos_incidence < np.cos(np.radians(40))).sum()) > 0


def test_measure_needs_one_generator_per_scan():
    with pytest.raises(ValueError, match="one generator per scan"):
        measure(_floor_hits(k=2), VLP16(), [np.random.default_rng(0)])
