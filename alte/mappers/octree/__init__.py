"""OctoMap's keys and trees, shared by Octomap and 3D-ALTE: keys, Morton codes and ray
traversal (:mod:`~alte.mappers.octree.raycast`), sets of keys as bit blocks
(:mod:`~alte.mappers.octree.blockset`), pruning and the ``.bt`` format
(:mod:`~alte.mappers.octree.tree`); and 3D-ALTE's packed cell keys and count tables
(:mod:`~alte.mappers.octree.celltable`)."""
