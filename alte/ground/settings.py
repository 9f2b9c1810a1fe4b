"""The ground filters' settings: one typed record per method, with its published defaults.

Every default is the one its source publishes, so ``--method smrf`` with no ``--set`` is
the filter a reader of the paper would run:

* :class:`SmrfSettings`: the Simple Morphological Filter, Pingel, Clarke & McBride (2013),
  ISPRS J. Photogramm. Remote Sens. 77, 21-30: 1 m cells, an 18 m largest window radius,
  slope 0.15, elevation threshold 0.5 m and scaling factor 1.25, the single parameter set
  with which the paper reports a mean Cohen's kappa of 85.4 % on the 15 ISPRS samples (the
  defaults PDAL's ``filters.smrf`` ships with).
* :class:`CsfSettings`: the Cloth Simulation Filter, Zhang et al. (2016), Remote Sens. 8(6),
  501: the defaults of the authors' own package (``cloth-simulation-filter``): 1 m cloth,
  rigidness 3 (flat terrain), slope post-processing on, 0.5 m class threshold, 500
  iterations, time step 0.65.
* :class:`MorphSettings`: alte's morphological baseline (a grey opening of the 1 m
  minimum raster with a 20 m square, Kilian et al. 1996, then a 1 m tolerance): the
  real-data chapter's filter before the field's filters came in.
* :class:`PlaneSettings`: the thesis' ground (2.1.4, 3.3.1): one MSAC plane with a 0.1 m
  inlier distance, tilted at most 30 degrees; a point within 0.3 m (the thesis' obstacle
  height) of it is ground.

:data:`DEFAULT_METHOD` and :data:`DEFAULT_SETTINGS` are the ground stage's choice on real
data (``alte.lab.studies.realdata.filters``; README "Ground"); a method named without settings
runs with its published defaults.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Literal

from alte.errors import ParameterError
from alte.params import Record, param

__all__ = ["DEFAULT_METHOD", "DEFAULT_SETTINGS", "METHODS", "SOURCES", "CsfSettings",
           "GroundSettings", "Method", "MorphSettings", "PlaneSettings", "SmrfSettings",
           "ground_settings"]

Method = Literal["smrf", "csf", "morph", "plane"]


@dataclass(frozen=True)
class SmrfSettings(Record):
    """SMRF (Pingel et al. 2013); defaults: the paper's single parameter set."""

    OWNER = "ground smrf"

    cell: float = param(1.0, lambda v: v > 0, "cell > 0", "raster cell of the minimum "
                        "surface (m)")
    window: float = param(18.0, lambda v: v > 0, "window > 0",
                          "largest opening radius (m): wider than the widest building")
    slope: float = param(0.15, lambda v: v >= 0, "slope >= 0",
                         "slope tolerance of the progressive opening (rise over run)")
    threshold: float = param(0.5, lambda v: v >= 0, "threshold >= 0",
                             "elevation threshold: largest height off the bare earth (m)")
    scalar: float = param(1.25, lambda v: v >= 0, "scalar >= 0",
                          "elevation scaling factor: the threshold grows by scalar x the "
                          "bare earth's slope")


@dataclass(frozen=True)
class CsfSettings(Record):
    """CSF (Zhang et al. 2016); defaults: the authors' package's."""

    OWNER = "ground csf"

    resolution: float = param(1.0, lambda v: v > 0, "resolution > 0",
                              "cloth grid spacing (m)")
    rigidness: int = param(3, lambda v: v in (1, 2, 3), "rigidness 1, 2 or 3",
                           "cloth rigidness: 1 steep slopes, 2 terraces, 3 flat terrain")
    slope_smooth: bool = param(True, help="post-process the cloth on steep slopes")
    threshold: float = param(0.5, lambda v: v > 0, "threshold > 0",
                             "largest distance to the cloth of a ground point (m)")
    iterations: int = param(500, lambda v: v >= 1, "iterations >= 1",
                            "cloth simulation steps")
    time_step: float = param(0.65, lambda v: 0 < v <= 1, "0 < time_step <= 1",
                             "simulation time step")


@dataclass(frozen=True)
class MorphSettings(Record):
    """alte's morphological baseline: opening of the minimum raster, then a tolerance."""

    OWNER = "ground morph"

    step: float = param(1.0, lambda v: v > 0, "step > 0", "raster cell (m)")
    window: float = param(20.0, lambda v: v > 0, "window > 0",
                          "side of the opening square (m): wider than the widest object")
    tolerance: float = param(1.0, lambda v: v >= 0, "tolerance >= 0",
                             "largest height off the opened surface of a ground point (m)")


@dataclass(frozen=True)
class PlaneSettings(Record):
    """The thesis' ground: one MSAC plane (2.1.4) and the obstacle height (3.3.1)."""

    OWNER = "ground plane"

    fit_threshold: float = param(0.1, lambda v: v > 0, "fit_threshold > 0",
                                 "MSAC inlier distance (m)")
    tolerance: float = param(0.3, lambda v: v >= 0, "tolerance >= 0",
                             "largest height off the plane of a ground point (m)")
    max_angle_deg: float = param(30.0, lambda v: 0 <= v <= 90, "0 <= max_angle_deg <= 90",
                                 "steepest plane accepted (degrees from level)")
    seed: int = param(0, help="MSAC's random draws")


GroundSettings = SmrfSettings | CsfSettings | MorphSettings | PlaneSettings

#: Method name -> its settings record.
METHODS: dict[str, type[GroundSettings]] = {
    "smrf": SmrfSettings, "csf": CsfSettings, "morph": MorphSettings, "plane": PlaneSettings}

#: Where each method's defaults come from (written into the output's provenance).
SOURCES: dict[str, str] = {
    "smrf": "Pingel, Clarke & McBride (2013), ISPRS J. Photogramm. Remote Sens. 77:21-30; "
            "pysmrf",
    "csf": "Zhang et al. (2016), Remote Sens. 8(6):501; cloth-simulation-filter",
    "morph": "alte's morphological baseline (Kilian et al. 1996 opening)",
    "plane": "the thesis' MSAC ground plane (2.1.4, 3.3.1)",
}

#: The ground stage's method and settings, chosen on real data: SMRF with a 0.10 slope
#: tolerance, the best of the published and nearby settings on the ISPRS samples (mean
#: kappa 91.1 % against 90.6 % for the published 0.15), checked on the ALS tiles (42.3 %
#: against 41.7 % agreement with the producers' class 2); README "Ground".
DEFAULT_METHOD: Method = "smrf"
DEFAULT_SETTINGS: GroundSettings = SmrfSettings(slope=0.10)


def ground_settings(method: str | None = None,
                    given: Mapping[str, object] | None = None) -> GroundSettings:
    """The settings record of ``method`` with ``given`` (text or typed values) applied to
    its published defaults; no method: the ground stage's default
    (:data:`DEFAULT_SETTINGS`). Unknown methods or keys raise :class:`ParameterError`."""
    if method is not None and method not in METHODS:
        raise ParameterError(f"ground: method={method!r} unknown; valid: "
                             f"{', '.join(METHODS)}")
    base = DEFAULT_SETTINGS if method is None else METHODS[method]()
    return base.replace(**dict(given)) if given else base
