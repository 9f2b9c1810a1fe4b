"""The Octomap family: the mapper (:mod:`~alte.mappers.octomap.mapper`), its two backends
(:mod:`~alte.mappers.octomap.backends`: ours and the C++ library's), one scan's ray casting
into key bits (:mod:`~alte.mappers.octomap.scan`, four rays at a time in
:mod:`~alte.mappers.octomap.lanes`) and the voxels' log-odds store
(:mod:`~alte.mappers.octomap.voxelstore`). The OctoMap keys and trees it shares with
3D-ALTE are in :mod:`alte.mappers.octree`.
"""

from alte.mappers.octomap.agreement import compare_backends
from alte.mappers.octomap.cells import occupied_voxels, read_bt
from alte.mappers.octomap.mapper import SENSOR_MODELS, Octomap, OctomapSettings

__all__ = ["SENSOR_MODELS", "Octomap", "OctomapSettings", "compare_backends", "occupied_voxels",
           "read_bt"]
