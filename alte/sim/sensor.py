"""Velodyne VLP-16 model (thesis 2.2.1, fig. 2.11) ray-cast with open3d.

Sensor frame as in the VLP-16 manual: azimuth ``a`` clockwise from +y, elevation
``w``; ``x = r cos w sin a``, ``y = r cos w cos a``, ``z = r sin w``. The 16 lasers
fire in the manual's order (-15, 1, -13, 3, ... deg); at 600 RPM (10 Hz) a firing
sequence advances 0.2 deg. The field of view is limited to 45 deg either side of +y
(thesis 2.2.1), giving 450 x 16 = 7200 rays a scan. Strongest return only: the first
surface hit. Simplifications (stated): the vehicle's motion during the 25 ms the beam
sweeps the field of view and the 2.3 us laser-to-laser azimuth drift are ignored;
each scan is taken from one sensor pose. Range noise is Gaussian (sigma = the data
sheet's 3 cm accuracy), truncated at 4 sigma. The ``uav`` sensor profile
(:mod:`alte.sim.profile`) lifts the first simplification: :func:`cast_sweep` casts each
firing from the pose at its own instant (:meth:`VLP16.firing_times`).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from alte.tensors import to_array, to_tensor

if TYPE_CHECKING:
    import open3d as o3d

__all__ = ["FIRING_ORDER_DEG", "FIRING_US", "VLP16", "Hits", "cast", "cast_sweep", "measure"]

#: Elevation (deg) of laser ids 0..15, in firing order (VLP-16 manual, table 9-1).
FIRING_ORDER_DEG = np.array([-15, 1, -13, 3, -11, 5, -9, 7, -7, 9, -5, 11, -3, 13, -1, 15],
                            dtype=np.float64)
#: Time between two lasers of one firing sequence (VLP-16 manual, 9.7), microseconds.
FIRING_US = 2.304


@dataclass(frozen=True)
class VLP16:
    """Sensor parameters; defaults are the thesis' operating point (fig. 2.12)."""

    rpm: float = 600.0
    azimuth_step_deg: float = 0.2
    fov_half_deg: float = 45.0
    max_range: float = 100.0
    min_range: float = 0.5
    range_sigma: float = 0.03
    noise_clip_sigma: float = 4.0
    max_incidence_deg: float = 86.0

    @property
    def rate_hz(self) -> float:
        """Rotations (scans) per second."""
        return self.rpm / 60.0

    def azimuths_deg(self) -> NDArray[np.float64]:
        """Firing azimuths inside the field of view, ``-fov <= a < fov``."""
        n = round(2 * self.fov_half_deg / self.azimuth_step_deg)
        return -self.fov_half_deg + self.azimuth_step_deg * np.arange(n, dtype=np.float64)

    def beams(self) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.intp]]:
        """Azimuth (deg), elevation (deg) and laser id of every ray, in firing order."""
        az = self.azimuths_deg()
        n_lasers = len(FIRING_ORDER_DEG)
        laser = np.tile(np.arange(n_lasers), len(az))
        return np.repeat(az, n_lasers), FIRING_ORDER_DEG[laser], laser

    def directions(self, azimuth_offset_deg: float = 0.0) -> NDArray[np.float64]:
        """Unit ray directions (M, 3) in the sensor frame, in firing order (azimuths
        shifted by ``azimuth_offset_deg``: the sub-rays of a beam's footprint)."""
        az, el, _ = self.beams()
        a, w = np.radians(az + azimuth_offset_deg), np.radians(el)
        return np.column_stack([np.cos(w) * np.sin(a), np.cos(w) * np.cos(a), np.sin(w)])

    def firing_times(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """When each firing sequence starts (G,) and each ray fires (M,), seconds after
        the start of the rotation at azimuth -180 deg (the scan stamp of a swept scan).

        The head turns at ``rpm``; the lasers of one sequence fire 2.304 us apart.
        """
        period = 60.0 / self.rpm
        group = (self.azimuths_deg() + 180.0) / 360.0 * period
        slot = np.arange(len(FIRING_ORDER_DEG)) * FIRING_US * 1e-6
        return group, (group[:, None] + slot[None, :]).reshape(-1)

    def to_dict(self) -> dict[str, float]:
        """Parameters for scenario.json."""
        return asdict(self)


@dataclass(frozen=True)
class Hits:
    """First-surface hits of K scans x M rays: distance (inf = miss), ``|cos|`` incidence,
    triangle."""

    distance: NDArray[np.float64]
    cos_incidence: NDArray[np.float64]
    triangle: NDArray[np.int64]


def cast(raycaster: o3d.t.geometry.RaycastingScene, positions: NDArray[np.float64],
         rotations: Rotation[tuple[int, ...]], directions: NDArray[np.float64]) -> Hits:
    """Cast the sensor's rays from K poses in one ``RaycastingScene.cast_rays`` call.

    ``positions`` (K, 3) and ``rotations`` (K) are the sensor poses in the scene
    frame, ``directions`` (M, 3) the rays in the sensor frame.
    """
    world = np.einsum("kij,mj->kmi", rotations.as_matrix().reshape(-1, 3, 3), directions)
    return _cast(raycaster, np.asarray(positions, dtype=np.float64), world)


def cast_sweep(raycaster: o3d.t.geometry.RaycastingScene, positions: NDArray[np.float64],
               rotations: Rotation[tuple[int, ...]], directions: NDArray[np.float64]) -> Hits:
    """Cast K swept scans: each of the G firing sequences from its own sensor pose.

    ``positions`` (K, G, 3) and ``rotations`` (K * G, row-major) are the sensor poses
    at each firing, ``directions`` (G * L, 3) the rays in firing order (L lasers a
    sequence). One ``cast_rays`` call for the whole batch; returns hits (K, G * L).
    """
    k, g = positions.shape[:2]
    rays = np.asarray(directions, dtype=np.float64).reshape(g, -1, 3)
    mats = rotations.as_matrix().reshape(k, g, 3, 3)
    world = np.einsum("kgij,glj->kgli", mats, rays).reshape(k, -1, 3)
    origins = np.repeat(np.asarray(positions, dtype=np.float64), rays.shape[1], axis=1)
    return _cast(raycaster, origins, world)


def _cast(raycaster: o3d.t.geometry.RaycastingScene, origins: NDArray[np.float64],
          world: NDArray[np.float64]) -> Hits:
    """First hits of rays from ``origins`` ((K, 3) or (K, M, 3)) along ``world`` (K, M, 3)."""
    k, m = world.shape[:2]
    if origins.ndim == 2:
        origins = np.broadcast_to(origins[:, None, :], (k, m, 3))
    rays = np.concatenate([origins, world], axis=2).reshape(-1, 6)
    out = raycaster.cast_rays(to_tensor(rays))
    dist = to_array(out["t_hit"], np.float64).reshape(k, m)
    normals = to_array(out["primitive_normals"], np.float64).reshape(k, m, 3)
    cos = np.abs(np.einsum("kmi,kmi->km", normals, world))
    tri = to_array(out["primitive_ids"], np.int64).reshape(k, m)
    tri[~np.isfinite(dist)] = -1
    return Hits(dist, cos, tri)


def measure(hits: Hits, sensor: VLP16, rngs: list[np.random.Generator]) -> tuple[
        NDArray[np.float64], dict[str, int]]:
    """Measured ranges (K, M), NaN where the sensor reports no return, and drop counts.

    No return for a miss, beyond ``max_range`` / below ``min_range``, or at grazing
    incidence (angle to the surface normal above ``max_incidence_deg``). Each scan
    draws its noise from its own generator so a scan's values do not depend on
    which other scans were simulated.
    """
    k, m = hits.distance.shape
    if len(rngs) != k:
        raise ValueError(f"need one generator per scan: {k} scans, {len(rngs)} generators")
    noise = np.stack([g.standard_normal(m) for g in rngs]) if k else np.zeros((0, m))
    clip = sensor.noise_clip_sigma
    ranges = hits.distance + sensor.range_sigma * np.clip(noise, -clip, clip)
    miss = ~np.isfinite(hits.distance)
    far = ~miss & ((hits.distance > sensor.max_range) | (hits.distance < sensor.min_range))
    grazing = ~miss & ~far & (hits.cos_incidence < np.cos(np.radians(sensor.max_incidence_deg)))
    ranges[miss | far | grazing] = np.nan
    counts = {"rays": k * m, "miss": int(miss.sum()), "out_of_range": int(far.sum()),
              "grazing": int(grazing.sum()), "returns": int(np.isfinite(ranges).sum())}
    return ranges, counts
