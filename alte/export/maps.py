"""Map messages: cube lists coloured by height and Octomap (the grids: :mod:`alte.export.grids`).

* :func:`cell_markers`: ``visualization_msgs/msg/MarkerArray``, one ``CUBE_LIST`` per
  cell size (a cube list has one scale), each cube coloured by its height (viridis
  over the shown cells' height range); a ``DELETEALL`` marker first, so a timeline
  update replaces the previous map. 2D cells (no thickness) are drawn as tiles.
* :func:`octomap_msg`: the Octomap mapper's maximum-likelihood binary tree, the
  payload of its ``.bt`` file, as ``octomap_msgs/msg/Octomap`` (binary, id ``OcTree``).
"""

from __future__ import annotations

import tempfile
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from alte.export.grids import height_colours
from alte.export.rosmsg import blank, header, pose, typestore
from alte.mappers import Cells, Octomap
from alte.types import rows_all

if TYPE_CHECKING:  # rosbags declares its message classes' type for checkers only
    from rosbags.typesys.store import MsgType

__all__ = ["CUBE_LIST", "DELETEALL", "cell_markers", "octomap_msg", "shown_cells"]

CUBE_LIST, ADD, DELETEALL = 6, 0, 3
#: Thickness of a 2D cell's tile, as a fraction of its edge.
TILE = 0.05
_BT_DATA = b"\ndata\n"


def shown_cells(cells: Cells, dims: int, everything: bool = False) -> NDArray[np.bool_]:
    """Mask of the cells drawn: occupied (3D maps) or known (2D height maps: a free leaf is
    ground at its height); ``everything`` adds the free cells of a 3D map."""
    known: NDArray[np.bool_] = rows_all(np.isfinite(cells.centers))
    if dims == 2 or everything:
        return known
    shown: NDArray[np.bool_] = known & np.asarray(cells.occupied, dtype=bool)
    return shown


def _cube_list(head: MsgType, ident: int, size: NDArray[np.float64], centers: NDArray[np.float64],
               colours: NDArray[np.float64]) -> MsgType:
    types = typestore().types
    point, rgba = types["geometry_msgs/msg/Point"], types["std_msgs/msg/ColorRGBA"]
    return blank("visualization_msgs/msg/Marker", header=head, ns="cells",
                 id=ident, type=CUBE_LIST, action=ADD,
                 pose=pose(np.zeros(3), np.array([0.0, 0.0, 0.0, 1.0])),
                 scale=types["geometry_msgs/msg/Vector3"](*map(float, size)),
                 color=rgba(1.0, 1.0, 1.0, 1.0),
                 points=[point(*map(float, c)) for c in centers],
                 colors=[rgba(*map(float, c)) for c in colours])


def cell_markers(cells: Cells, mask: NDArray[np.bool_], stamp: int, frame: str,
                 shift: NDArray[np.float64]) -> MsgType:
    """MarkerArray of the masked cells (centres moved back by the local ``shift``)."""
    centers = cells.centers[mask] + shift
    sizes = cells.sizes[mask].copy()
    flat = sizes[:, 2] == 0
    sizes[flat, 2] = TILE * sizes[flat, 0]
    colours = height_colours(centers[:, 2])
    groups, which = np.unique(sizes, axis=0, return_inverse=True)
    markers = [blank("visualization_msgs/msg/Marker", header=header(stamp, frame), ns="cells",
                     action=DELETEALL)]
    for g, size in enumerate(groups):
        sel = which.reshape(-1) == g
        markers.append(_cube_list(header(stamp, frame), g, size, centers[sel], colours[sel]))
    return typestore().types["visualization_msgs/msg/MarkerArray"](markers)


def octomap_msg(mapper: Octomap, stamp: int, frame: str) -> MsgType:
    """The binary tree of ``mapper`` (its ``.bt`` payload) as ``octomap_msgs/msg/Octomap``."""
    with tempfile.TemporaryDirectory() as tmp:
        path = mapper.write_bt(Path(tmp) / "map.bt")
        content = path.read_bytes()
    start = content.index(_BT_DATA) + len(_BT_DATA)
    data = np.frombuffer(content[start:], dtype=np.int8).copy()
    return blank("octomap_msgs/msg/Octomap", header=header(stamp, frame), binary=True,
                 id="OcTree", resolution=float(mapper.voxel_size), data=data)
