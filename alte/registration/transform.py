"""Eq. 2.2 of the thesis: sensor-frame points -> inertial points, and back.

``R_P^I = R_B^I + [DCM]_B^I R_S/B^B + [DCM]_B^I [DCM]_S^B R_P/S^S`` for every point of a
scan, with the body pose of the :class:`~alte.types.Frame` and the sensor
:class:`~alte.types.Mount`.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from alte.types import Frame, Mount

__all__ = ["register_frame", "register_with_origin", "sensor_origin", "sensor_pose", "to_sensor"]


def sensor_pose(frame: Frame, mount: Mount) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Sensor-to-inertial matrix ``[DCM]_B^I [DCM]_S^B`` and the sensor origin in I."""
    body = frame.rotation.as_matrix()
    matrix = body @ mount.rotation.as_matrix()
    origin = np.asarray(frame.position, dtype=np.float64) + body @ mount.translation
    return matrix, origin


def register_frame(frame: Frame, mount: Mount) -> NDArray[np.float64]:
    """Eq. 2.2: R_P^I = R_B^I + DCM_B^I R_S/B^B + DCM_B^I DCM_S^B R_P/S^S for every point."""
    return register_with_origin(frame, mount)[0]


def register_with_origin(frame: Frame, mount: Mount,
                         ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """:func:`register_frame` and :func:`sensor_origin` from one evaluation of the pose."""
    matrix, origin = sensor_pose(frame, mount)
    points = np.asarray(frame.points, dtype=np.float64).reshape(-1, 3)
    registered: NDArray[np.float64] = points @ matrix.T + origin
    return registered, origin


def sensor_origin(frame: Frame, mount: Mount) -> NDArray[np.float64]:
    """The sensor position in the inertial frame, R_B^I + DCM_B^I R_S/B^B (3,)."""
    return sensor_pose(frame, mount)[1]


def to_sensor(points: NDArray[np.float64], frame: Frame, mount: Mount) -> NDArray[np.float64]:
    """Inverse of :func:`register_frame`: inertial points back into the sensor frame."""
    matrix, origin = sensor_pose(frame, mount)
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    local: NDArray[np.float64] = (pts - origin) @ matrix
    return local
