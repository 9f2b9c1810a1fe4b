"""Synthetic frames with known poses and mount, built with independent (hand-written) math.

Shared by the registration tests and the ``alte register`` command tests; ``tests/`` is on
``sys.path`` through pytest's ``pythonpath`` setting.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from alte.types import Frame, Mount

__all__ = ["make_frame", "quat_matrix", "scene"]


def quat_matrix(q: np.ndarray) -> np.ndarray:
    """Rotation matrix of a unit quaternion (x, y, z, w), written out by hand."""
    x, y, z, w = np.asarray(q, dtype=float) / np.linalg.norm(q)
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])


def make_frame(points, position=(0, 0, 0), quat=(0, 0, 0, 1), *, stamp=0, rate=0.0, offset=0.0):
    return Frame(
        stamp=stamp, points=np.asarray(points, float).reshape(-1, 3),
        position=np.asarray(position, float), quaternion=np.asarray(quat, float),
        pose_offset_s=offset, angular_rate=rate,
    )


def scene(seed: int = 0, frames: int = 6, n: int = 200):
    """Inertial points per frame, poses, a mount, and frames built by hand in the sensor frame."""
    rng = np.random.default_rng(seed)
    mount = Mount(np.array([0.2, -0.1, -0.05]), Rotation.random(random_state=seed).as_quat())
    mount_m = quat_matrix(mount.quaternion)
    truth, out = [], []
    for k in range(frames):
        quat = Rotation.random(random_state=seed + 100 + k).as_quat()
        position = rng.uniform(-10, 10, 3)
        inertial = rng.uniform(-5, 5, (n, 3))
        body_m = quat_matrix(quat)
        origin = position + body_m @ mount.translation
        sensor = np.array([(body_m @ mount_m).T @ (p - origin) for p in inertial])
        truth.append(inertial)
        out.append(make_frame(sensor, position, quat, stamp=k * 100_000_000))
    return truth, out, mount
