"""Results for the field's tools: one ROS 2 MCAP file that Foxglove Studio and RViz open.

:mod:`~alte.export.rosmsg` builds ROS messages from arrays (plus the Octomap and
GridMap definitions rosbags lacks), :mod:`~alte.export.maps` the map messages,
:mod:`~alte.export.mcap` writes the file (topics listed there) and
:mod:`~alte.export.run` exports a map run (growing on a timeline) or a registration.
"""

from alte.export.mcap import MAP_TOPICS, TOPICS, McapFile
from alte.export.run import (
    ExportSettings,
    MapExporter,
    export_map,
    export_registered,
    timeline_feed,
)

__all__ = ["MAP_TOPICS", "TOPICS", "ExportSettings", "MapExporter", "McapFile", "export_map",
           "export_registered", "timeline_feed"]
