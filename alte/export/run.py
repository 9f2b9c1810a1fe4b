"""Export a map run or a registration as one MCAP (topics in :mod:`alte.export.mcap`).

:func:`export_map` runs the pipeline (:func:`alte.pipeline.run`) with a
:class:`MapExporter` as its frame observer: every mapped scan goes out as it is
mapped (scan, pose, TF) and, with a timeline, the map every ``N`` scans. The final
map, the whole trajectory and the merged cloud are written twice: at the file's start
time (so a viewer shows them from the first instant) and at its last scan (so they
are the latest state at the end, after a timeline's growth). :func:`export_registered`
writes a registration without a map (``alte register --mcap``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from alte.errors import ParameterError
from alte.export import grids, maps
from alte.export.mcap import McapFile
from alte.export.rosmsg import cloud_msg, path_msg, pose_stamped, tf_msg
from alte.ground.surface import OccupancySettings
from alte.mappers import Feed, Mapper, Octomap
from alte.params import Record, param
from alte.pipeline import FrameSettings, MapRun, MapSettings, Registered, Source, run
from alte.types import RegisteredFrame

__all__ = ["BODY", "LOCAL", "WORLD", "ExportSettings", "MapExporter", "export_map",
           "export_registered", "timeline_feed"]

WORLD, BODY, LOCAL = "map", "base_link", "alte_local"
_IDENTITY = np.array([0.0, 0.0, 0.0, 1.0])


@dataclass(frozen=True)
class ExportSettings(Record):
    """What an MCAP export writes besides the final map and the trajectory."""

    OWNER = "export"

    timeline: int | None = param(None, lambda v: v >= 1, "timeline >= 1",
                                 "a map update every that many mapped scans (None: the final "
                                 "map only)")
    scans: bool = param(True, help="write each registered scan")
    all_cells: bool = param(False, help="free cells of 3D maps too")
    max_grid_cells: int = param(4_000_000, lambda v: v >= 1, "max_grid_cells >= 1",
                                "largest 2D grid (cells; coarsened by powers of two beyond it)")
    surface: OccupancySettings = param(OccupancySettings(), help="the landing criterion that "
                                       "makes grid cells free or occupied")


class MapExporter:
    """Frame observer writing scans, poses and (on the timeline) the growing map."""

    def __init__(self, out: McapFile, options: ExportSettings) -> None:
        self.out, self.options = out, options
        self.poses: list[RegisteredFrame] = []
        self.last_map: int | None = None

    def frame(self, frame: RegisteredFrame) -> None:
        """One registered scan: its points, body pose and ``map -> base_link``."""
        stamp = int(frame.stamp)
        if self.options.scans:
            self.out.put("/alte/scan", stamp, cloud_msg(frame.points, stamp, WORLD))
        self.out.put("/alte/pose", stamp,
                     pose_stamped(stamp, WORLD, frame.position, frame.quaternion))
        self.out.put("/tf", stamp, tf_msg(stamp, WORLD, BODY, frame.position, frame.quaternion))
        self.poses.append(RegisteredFrame(stamp, np.empty((0, 3)), frame.origin,
                                          frame.position, frame.quaternion))

    def __call__(self, index: int, frame: RegisteredFrame, mapper: Mapper,
                 shift: NDArray[np.float64]) -> None:
        self.frame(frame)
        every = self.options.timeline
        if every is not None and (index + 1) % every == 0:
            self.map(index, mapper, shift)

    def trajectory(self, stamp: int, opening: bool = False) -> None:
        """The path through every pose so far."""
        p = self.poses
        self.out.put("/alte/trajectory", stamp, path_msg(
            stamp, WORLD, np.array([f.stamp for f in p]), np.array([f.position for f in p]),
            np.array([f.quaternion for f in p])), opening)

    def map(self, index: int, mapper: Mapper, shift: NDArray[np.float64], stamp: int | None = None,
            opening: bool = False) -> None:
        """The map after mapped scan ``index``, stamped with that scan's time (or ``stamp``,
        with ``opening``: kept for the start of the file)."""
        at = int(self.poses[index].stamp) if stamp is None else stamp
        cells, put = mapper.cells(), self._put(at, opening)
        mask = maps.shown_cells(cells, mapper.dims, self.options.all_cells)
        put("/alte/map/cells", maps.cell_markers(cells, mask, at, WORLD, shift))
        if np.isfinite(cells.centers).all(axis=1).any():
            grid = grids.raster(cells, shift, self.options.max_grid_cells, mapper.dims,
                                self.options.surface)
            put("/alte/map/occupancy", grids.occupancy_grid(grid, at, WORLD))
            put("/alte/map/grid", grids.foxglove_grid(grid, at, WORLD))
            if mapper.dims == 2:
                put("/alte/map/grid_map", grids.grid_map(grid, at, WORLD))
        if isinstance(mapper, Octomap):
            frame = LOCAL if np.any(shift) else WORLD
            put("/alte/map/octomap", maps.octomap_msg(mapper, at, frame))
        self.trajectory(at, opening)
        if not opening:
            self.last_map = index

    def _put(self, stamp: int, opening: bool) -> Callable[[str, object], None]:
        """``put(topic, message)`` at ``stamp``, streamed or kept for the opening."""
        return lambda topic, message: self.out.put(topic, stamp, message, opening)

    def finish(self, mapper: Mapper | None, shift: NDArray[np.float64],
               cloud: NDArray[np.float64] | None) -> None:
        """The final map (unless the timeline just wrote it), merged cloud and trajectory,
        at the last scan and again at the first (the opening)."""
        if not self.poses:
            return
        last, first = len(self.poses) - 1, int(self.poses[0].stamp)
        stamp = int(self.poses[last].stamp)
        if np.any(shift):
            self.out.put("/tf_static", first, tf_msg(first, WORLD, LOCAL, shift, _IDENTITY),
                         opening=True)
        if mapper is not None:
            if self.last_map != last:
                self.map(last, mapper, shift)
            self.map(last, mapper, shift, stamp=first, opening=True)
        else:
            self.trajectory(stamp)
            self.trajectory(first, opening=True)
        if cloud is not None:
            self.out.put("/alte/cloud", stamp, cloud_msg(cloud, stamp, WORLD))
            self.out.put("/alte/cloud", first, cloud_msg(cloud, first, WORLD), opening=True)


def timeline_feed(spec: MapSettings, options: ExportSettings) -> MapSettings:
    """``spec`` as an export with ``options`` maps: a timeline needs the map fed scan by
    scan, so a default batch feed is switched and an explicit one refused."""
    if options.timeline is None or (spec.feed or spec.cls.default_feed) \
            is Feed.FRAMES:
        return spec
    if spec.feed is Feed.BATCH:
        raise ParameterError("export: a timeline needs feed=frames (a batch build has no map "
                             "before the last scan)")
    return replace(spec, feed=Feed.FRAMES)


def export_map(source: Source | Registered, target: Path, spec: MapSettings,
               frames: FrameSettings | None = None, *, options: ExportSettings | None = None,
               cache: Path | None = None, overwrite: bool = False,
               progress: bool = False) -> tuple[MapRun, dict[str, int]]:
    """Map ``source`` as :func:`alte.pipeline.run` does and write the MCAP ``target``;
    returns the run and the message count per topic."""
    options = options or ExportSettings()
    spec = timeline_feed(spec, options)
    with McapFile(target, overwrite) as out:
        exporter = MapExporter(out, options)
        result = run(source, spec, frames, cache=cache, cloud=True, progress=progress,
                     observer=exporter)
        exporter.finish(result.mapper, np.asarray(result.info.local_origin), result.cloud)
    return result, dict(out.counts)


def export_registered(reg: Registered, target: Path, *, options: ExportSettings | None = None,
                      overwrite: bool = False) -> dict[str, int]:
    """Write a registration (scans, poses, trajectory, merged cloud) without a map."""
    with McapFile(target, overwrite) as out:
        exporter = MapExporter(out, options or ExportSettings())
        for frame in reg.frames():
            exporter.frame(frame)
        exporter.finish(None, np.zeros(3), np.asarray(reg.cloud))
    return dict(out.counts)
