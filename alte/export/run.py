"""Export a map run or a registration as one MCAP (topics in :mod:`alte.export.mcap`).

:func:`export_map` runs the pipeline (:func:`alte.pipeline.run`) with a
:class:`MapExporter` as its frame observer: every mapped scan goes out as it is
mapped (scan, pose, TF) and, with a timeline, the map every ``N`` scans; the final
map, the merged cloud and the whole trajectory close the file. :func:`export_registered`
writes a registration without a map (``alte register --mcap``).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from alte.errors import ParameterError
from alte.export import maps
from alte.export.mcap import McapFile
from alte.export.rosmsg import cloud_msg, path_msg, pose_stamped, tf_msg
from alte.mappers import Feed, Mapper, Octomap, mapper_class
from alte.pipeline import FrameSpec, MapRun, MapSpec, Registered, Source, run
from alte.types import RegisteredFrame

__all__ = ["BODY", "LOCAL", "WORLD", "ExportOptions", "MapExporter", "export_map",
           "export_registered"]

WORLD, BODY, LOCAL = "map", "base_link", "alte_local"
_IDENTITY = np.array([0.0, 0.0, 0.0, 1.0])


@dataclass(frozen=True)
class ExportOptions:
    """``timeline``: a map update every that many mapped scans (None: the final map only);
    ``scans``: write each registered scan; ``all_cells``: free cells of 3D maps too;
    ``max_grid_cells``: largest 2D grid (coarsened by powers of two beyond it)."""

    timeline: int | None = None
    scans: bool = True
    all_cells: bool = False
    max_grid_cells: int = 4_000_000

    def __post_init__(self) -> None:
        t = self.timeline
        if t is not None and (isinstance(t, bool) or not isinstance(t, int) or t < 1):
            raise ParameterError(f"--timeline {t!r}: expected a positive number of scans")


class MapExporter:
    """Frame observer writing scans, poses and (on the timeline) the growing map."""

    def __init__(self, out: McapFile, options: ExportOptions) -> None:
        self.out, self.options = out, options
        self.poses: list[RegisteredFrame] = []
        self.last_map: int | None = None
        self.local_sent = False

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
                 shift: np.ndarray) -> None:
        self.frame(frame)
        every = self.options.timeline
        if every is not None and (index + 1) % every == 0:
            self.map(index, mapper, shift)

    def trajectory(self, stamp: int) -> None:
        """The path through every pose so far."""
        p = self.poses
        self.out.put("/alte/trajectory", stamp, path_msg(
            stamp, WORLD, np.array([f.stamp for f in p]), np.array([f.position for f in p]),
            np.array([f.quaternion for f in p])))

    def map(self, index: int, mapper: Mapper, shift: np.ndarray) -> None:
        """The map after mapped scan ``index``, stamped with that scan's time."""
        stamp = int(self.poses[index].stamp)
        cells = mapper.cells()
        mask = maps.shown_cells(cells, mapper.dims, self.options.all_cells)
        self.out.put("/alte/map/cells", stamp, maps.cell_markers(cells, mask, stamp, WORLD,
                                                                 shift))
        if mapper.dims == 2 and np.isfinite(cells.centers[:, 2]).any():
            grid = maps.raster(cells, shift, self.options.max_grid_cells)
            self.out.put("/alte/map/occupancy", stamp, maps.occupancy_grid(grid, stamp, WORLD))
            self.out.put("/alte/map/grid_map", stamp, maps.grid_map(grid, stamp, WORLD))
        if isinstance(mapper, Octomap):
            self.out.put("/alte/map/octomap", stamp,
                         maps.octomap_msg(mapper, stamp, self._local(stamp, shift)))
        self.trajectory(stamp)
        self.last_map = index

    def _local(self, stamp: int, shift: np.ndarray) -> str:
        """The frame of a map kept in local coordinates (``map`` when not shifted)."""
        if not np.any(shift):
            return WORLD
        if not self.local_sent:
            self.out.put("/tf_static", stamp, tf_msg(stamp, WORLD, LOCAL, shift, _IDENTITY))
            self.local_sent = True
        return LOCAL

    def finish(self, mapper: Mapper | None, shift: np.ndarray, cloud: np.ndarray | None) -> None:
        """The final map (unless the timeline just wrote it), merged cloud and trajectory."""
        if not self.poses:
            return
        last = len(self.poses) - 1
        stamp = int(self.poses[last].stamp)
        if mapper is not None and self.last_map != last:
            self.map(last, mapper, shift)
        elif mapper is None:
            self.trajectory(stamp)
        if cloud is not None:
            self.out.put("/alte/cloud", stamp, cloud_msg(cloud, stamp, WORLD))


def _frames_feed(spec: MapSpec, options: ExportOptions) -> MapSpec:
    """A timeline needs the map fed scan by scan: switch a default batch feed, refuse an
    explicit one."""
    if options.timeline is None or (spec.feed or mapper_class(spec.mapper).default_feed) \
            is Feed.FRAMES:
        return spec
    if spec.feed is Feed.BATCH:
        raise ParameterError("--timeline needs the map fed scan by scan: use --feed frames "
                             "(a batch build has no map before the last scan)")
    return replace(spec, feed=Feed.FRAMES)


def export_map(source: Source | Registered, target: Path, spec: MapSpec,
               frames: FrameSpec | None = None, *, options: ExportOptions | None = None,
               cache: Path | None = None, overwrite: bool = False,
               progress: bool = False) -> tuple[MapRun, dict[str, int]]:
    """Map ``source`` as :func:`alte.pipeline.run` does and write the MCAP ``target``;
    returns the run and the message count per topic."""
    options = options or ExportOptions()
    spec = _frames_feed(spec, options)
    with McapFile(target, overwrite) as out:
        exporter = MapExporter(out, options)
        result = run(source, spec, frames, cache=cache, cloud=True, progress=progress,
                     observer=exporter)
        exporter.finish(result.mapper, np.asarray(result.info.local_origin), result.cloud)
    return result, dict(out.counts)


def export_registered(reg: Registered, target: Path, *, options: ExportOptions | None = None,
                      overwrite: bool = False) -> dict[str, int]:
    """Write a registration (scans, poses, trajectory, merged cloud) without a map."""
    with McapFile(target, overwrite) as out:
        exporter = MapExporter(out, options or ExportOptions())
        for frame in reg.frames():
            exporter.frame(frame)
        exporter.finish(None, np.zeros(3), np.asarray(reg.cloud))
    return dict(out.counts)
