"""The height variance of one LiDAR point: a laser's noise along and across its beam.

The model is the one ETH's ``elevation_mapping`` applies to laser range sensors
(``LaserSensorProcessor``, after Pomerleau, Breitenmoser, Liu, Colas & Siegwart, "Noise
characterization of depth sensors for surface inspections", CARPI 2012):

* along the beam the standard deviation is a constant, ``range_sigma`` (their
  ``min_radius``);
* across it, the beam's footprint grows with the distance ``d``:
  ``lateral_sigma = beam_constant + beam_angle * d``.

``elevation_mapping`` projects that covariance on the map's vertical through the sensor
frame's fixed axes (built for a camera looking along its z axis). A spinning LiDAR's
beams point every way, so here the covariance is set along each point's own beam, unit
vector ``u`` from the sensor origin to the point, and projected on the vertical:

    height variance = range_sigma^2 * u_z^2 + lateral_sigma(d)^2 * (1 - u_z^2)

A beam straight down measures height with its range noise; a grazing beam (``u_z``
near 0) with its footprint, which grows with the distance: the range- and
angle-dependence of the model. A point given without its origin (a bare cloud) is
taken as seen from straight above at no distance: ``range_sigma^2``.

(``elevation_mapping_cupy`` models a point's variance as ``sensor_noise_factor * z^2``,
default 0.05, with ``z`` the point's coordinate along the sensor frame's z axis: a depth
camera's depth. For a LiDAR in its own frame ``z`` is the point's height above the
sensor, not a range, so that model is not used here.)
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

__all__ = ["point_variance"]


def point_variance(points: NDArray[np.float64], origins: NDArray[np.float64] | None,
                   range_sigma: float, beam_constant: float,
                   beam_angle: float) -> NDArray[np.float64]:
    """Height variance (m^2) of each point (N, 3) seen from ``origins`` (N, 3) (module
    docstring; None: every point from straight above)."""
    n = len(points)
    if origins is None:
        return np.full(n, range_sigma**2)
    ray = points - origins
    dist2 = np.einsum("ij,ij->i", ray, ray)
    uz2 = np.divide(ray[:, 2] ** 2, dist2, out=np.ones(n), where=dist2 > 0)
    lateral = (beam_constant + beam_angle * np.sqrt(dist2)) ** 2
    variance: NDArray[np.float64] = range_sigma**2 * uz2 + lateral * (1.0 - uz2)
    return variance
