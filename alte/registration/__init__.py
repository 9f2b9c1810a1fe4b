"""Registration (thesis 2.1.2-2.1.3): posed sensor frames -> one inertial cloud.

:mod:`~alte.registration.transform` is eq. 2.2, :mod:`~alte.registration.grid` the
grid-average and box-grid filters, :mod:`~alte.registration.register` the frame stream
(crop, manoeuvre filter, down-sampling) and the merged cloud.
"""

from alte.registration.grid import (
    GridAccumulator,
    box_grid_merge,
    check_voxel,
    grid_average,
    grid_average_with_counts,
)
from alte.registration.register import (
    ManoeuvreFilter,
    Registration,
    RegistrationCounts,
    check_options,
    crop,
    crop_mask,
    empty_reason,
    register,
    register_frames,
)
from alte.registration.transform import register_frame, sensor_origin, sensor_pose, to_sensor

__all__ = [
    "GridAccumulator",
    "ManoeuvreFilter",
    "Registration",
    "RegistrationCounts",
    "box_grid_merge",
    "check_options",
    "check_voxel",
    "crop",
    "crop_mask",
    "empty_reason",
    "grid_average",
    "grid_average_with_counts",
    "register",
    "register_frame",
    "register_frames",
    "sensor_origin",
    "sensor_pose",
    "to_sensor",
]
