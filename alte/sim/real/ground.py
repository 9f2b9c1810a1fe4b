"""The terrain import's ground: which points of the tiles are bare earth, and how that was told.

* A LAS/LAZ tile keeps its producer's classification: class 2 (ASPRS ground), or the class
  ``--ground-class N`` names. A tile with no point of class 2 is classified with the ground
  stage's filter (:func:`alte.ground.filters.filter_ground`: its default method and
  settings, or those ``--ground-method`` / ``--ground-set`` name). A class named on purpose
  that no point holds is refused, not silently replaced by a filter.
* Naming a method (``--ground-method``) classifies every LAS/LAZ tile with that filter,
  replacing the producer's ground class (its other classes still name the objects).
* An ISPRS-style pair's ground is its ground file and a DEM is bare earth: no filter.

The filter runs once on the points of all the tiles it classifies together, after
``--region``: overlaps and seams are one cloud, and nothing outside the crop is filtered.
:func:`terrain_tiles` returns the tiles and the record of how their ground was told for
scenario.json; the filter's part is what ``alte ground`` writes into a classified tile's
header (:meth:`~alte.ground.filters.GroundResult.provenance`).
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from alte.errors import GroundError, ParameterError, PointFileError
from alte.ground.filters import filter_ground
from alte.ground.settings import DEFAULT_METHOD, METHODS, GroundSettings, ground_settings
from alte.sim.real.tiles import GROUND_CLASS, Tile, read_tiles
from alte.types import JSONDict

__all__ = ["GroundChoice", "crop_tiles", "terrain_tiles"]

_METHOD_OF = {cls: name for name, cls in METHODS.items()}


@dataclass(frozen=True)
class GroundChoice:
    """How the import tells ground (module docstring): ``ground_class`` names the class
    (None: class 2, and the filter where a tile has none); ``method`` names the filter
    and forces it on every LAS/LAZ tile; ``settings`` are the filter's (None: the named
    method's published defaults, or the ground stage's default method and settings)."""

    ground_class: int | None = None
    method: str | None = None
    settings: GroundSettings | None = None

    def __post_init__(self) -> None:
        if self.ground_class is not None and not 0 <= self.ground_class <= 255:
            raise ParameterError(f"import: ground_class={self.ground_class}: an ASPRS class "
                                 "is 0 to 255 (ground is 2)", setting="import.ground_class")
        if self.ground_class is not None and self.uses_filter:
            raise ParameterError("import: ground_class and a ground filter (method, "
                                 "settings) exclude each other: the named class is the "
                                 "tiles' ground, the filter replaces it",
                                 setting=("import.ground_class", "import.ground_method",
                                          "import.ground_settings"))
        if self.method is not None and self.method not in METHODS:
            raise ParameterError(f"import: ground method {self.method!r} unknown; valid: "
                                 f"{', '.join(METHODS)}", setting="import.ground_method")
        if self.method is not None and self.settings is not None and \
                not isinstance(self.settings, METHODS[self.method]):
            raise ParameterError(f"import: {type(self.settings).__name__} are not the "
                                 f"settings of the ground method {self.method}",
                                 setting="import.ground_settings")

    @property
    def uses_filter(self) -> bool:
        """A filter method or settings were named."""
        return self.method is not None or self.settings is not None

    def filter(self) -> tuple[str, GroundSettings]:
        """The filter's method and settings."""
        if self.settings is not None:
            return self.method or _METHOD_OF[type(self.settings)], self.settings
        return self.method or DEFAULT_METHOD, ground_settings(self.method)

    def policy(self) -> str:
        """The rule in words, for scenario.json."""
        if self.method is not None:
            return (f"the {self.method} filter on every LAS/LAZ tile, replacing the "
                    "producer's ground class")
        if self.ground_class is not None:
            return f"class {self.ground_class} (named)"
        return (f"class {GROUND_CLASS} where a tile has it, else the "
                f"{self.filter()[0]} filter")


def _no_class(tile: Tile, ground_class: int) -> PointFileError:
    held = np.unique(tile.classes, return_counts=True)
    present = ", ".join(f"{c} ({n:,} points)" for c, n in zip(*held, strict=True))
    return PointFileError(
        f"{tile.path}: no point of ground class {ground_class} (classes present: "
        f"{present or 'none'}); name the class its ground is (ground_class), give its "
        "bare-earth points (a ground file), or leave ground_class out to classify it with "
        f"the ground filter ({DEFAULT_METHOD}, or another ground method)",
        setting="import.ground_class")


def _filtered(tile: Tile, choice: GroundChoice) -> bool:
    """Whether the filter classifies ``tile`` (module docstring)."""
    if tile.kind != "las":
        return False
    if choice.method is not None:
        return True
    if tile.ground.any():
        return False
    if choice.ground_class is not None:
        raise _no_class(tile, choice.ground_class)
    return True


def _classify(tiles: list[Tile], pending: list[int], choice: GroundChoice
              ) -> tuple[list[Tile], JSONDict]:
    """The tiles ``pending`` classified together by the filter, and its provenance."""
    method, settings = choice.filter()
    chosen = [tiles[i] for i in pending]
    names = ", ".join(str(t.path) for t in chosen)
    try:
        result = filter_ground(np.vstack([t.points for t in chosen]), method, settings)
    except GroundError as err:
        raise GroundError(f"{names}: the ground filter cannot classify it ({err}); if "
                          "every point is bare earth, name their class (ground_class)",
                          setting="import.ground_class") from err
    if not result.ground.any():
        raise GroundError(f"{names}: the {method} filter calls no point ground; check the "
                          "tile's units and noise, or try another ground method",
                          setting="import.ground_method")
    parts = np.split(result.ground, np.cumsum([len(t.points) for t in chosen])[:-1])
    out = list(tiles)
    for i, mask in zip(pending, parts, strict=True):
        out[i] = replace(tiles[i], ground=mask, ground_by=f"filter {method}")
    record: JSONDict = {**result.provenance(), "cpu_s": round(result.cpu_s, 3),
                        "tiles": [str(t.path) for t in chosen]}
    return out, record


def crop_tiles(tiles: list[Tile], region: Sequence[float] | None) -> list[Tile]:
    """Each tile's points inside ``region`` (x0, y0, x1, y1 in the tiles' CRS units)."""
    if region is None:
        return tiles
    x0, y0, x1, y1 = (float(region[i]) for i in range(4))
    if not (x1 > x0 and y1 > y0):
        raise ParameterError(f"import: region={list(region)}: expected XMIN,YMIN,XMAX,YMAX "
                             "with XMIN < XMAX and YMIN < YMAX", setting="import.region")
    out = []
    for t in tiles:
        f = t.units.horizontal_m
        x, y = t.points[:, 0], t.points[:, 1]
        keep = (x >= x0 * f) & (x <= x1 * f) & (y >= y0 * f) & (y <= y1 * f)
        if keep.any():
            out.append(replace(t, points=t.points[keep], classes=t.classes[keep],
                               first=t.first[keep], ground=t.ground[keep],
                               notes=[*t.notes, f"cropped to the region {x0:g},{y0:g},{x1:g},"
                                      f"{y1:g}"]))
    if not out:
        raise ParameterError(f"import: region={list(region)}: no tile has points inside it "
                             "(the region is in the tiles' CRS units)", setting="import.region")
    return out


def terrain_tiles(paths: Sequence[str | os.PathLike[str]], *, crs: str | None = None,
                  ground: str | os.PathLike[str] | None = None,
                  choice: GroundChoice | None = None, region: Sequence[float] | None = None
                  ) -> tuple[list[Tile], JSONDict]:
    """The tiles read, cropped to ``region`` and their ground told by ``choice`` (module
    docstring); with the record of how, for scenario.json."""
    choice = choice or GroundChoice()
    if ground is not None and choice.uses_filter:
        raise ParameterError("import: a ground file and a ground filter (method, settings) "
                             "exclude each other: the file is the tile's ground",
                             setting=("import.ground_file", "import.ground_method",
                                      "import.ground_settings"))
    named = choice.ground_class if choice.ground_class is not None else GROUND_CLASS
    tiles = crop_tiles(read_tiles(list(paths), crs=crs, ground=ground, ground_class=named),
                       region)
    pending = [i for i, t in enumerate(tiles) if _filtered(t, choice)]
    record: JSONDict = {"policy": choice.policy() if ground is None else "the ground file",
                        "class": named if ground is None else None,
                        "file": str(ground) if ground is not None else None, "filter": None}
    if pending:
        tiles, record["filter"] = _classify(tiles, pending, choice)
    elif choice.method is not None:
        raise ParameterError(f"import: ground method {choice.method}: no LAS/LAZ tile to "
                             "classify (a DEM is bare earth already); leave it out",
                             setting="import.ground_method")
    elif choice.uses_filter:
        raise ParameterError(f"import: ground settings: every tile has ground class "
                             f"{GROUND_CLASS} or is a DEM, so no filter runs; name the ground "
                             "method to reclassify the LAS/LAZ tiles with it",
                             setting="import.ground_settings")
    return tiles, record
