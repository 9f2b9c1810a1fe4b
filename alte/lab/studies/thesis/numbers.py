"""The thesis' own numbers, as data: tables 5.1-5.12 and the chapter 4 mapper parameters.

Everything here is transcribed from "Adaptive Learning Terrain Estimation for UAV
Applications" (chapters 4 and 5) so that our measurements can be printed beside it.
Parameter names are those of :mod:`alte.mappers` (``max_points``, ``resolution``,
``kappa``/``max_res``/``min_pts``, ``min_pts``/``min_pts_split``/``max_res``).
Note: the thesis' column "MHD - HD" in tables 5.10/5.11 holds HD - MHD (e.g.
5.308 - 1.090 = 4.218), so it is stored here as ``hd_minus_mhd_m``.
"""

from __future__ import annotations

from typing import TypedDict

import pandas as pd

from alte.errors import ParameterError
from alte.sim.terrains import TERRAINS

__all__ = [
    "CASE_MAPPERS",
    "CH4_PARAMS",
    "COMPARISONS",
    "POINT_CLOUDS",
    "QUALITATIVE",
    "SWEEPS",
    "TERRAIN_CASE",
    "MapperParams",
    "PointCloudRef",
    "Sweep",
    "SweepRow",
    "mapper_params",
    "qualitative_table",
    "sweep_table",
]

#: Parameters of one mapper by name, as the thesis gives them (all numbers).
MapperParams = dict[str, float]

#: One row of a sweep table: (params, elapsed s, basis functions, HD m, MHD m).
SweepRow = tuple[MapperParams, float, int, float, float]


class Sweep(TypedDict):
    """A sweep table of chapter 5 (5.7, 5.8, 5.9, 5.12): one mapper on one terrain."""

    mapper: str
    terrain: str
    rows: list[SweepRow]


class PointCloudRef(TypedDict):
    """The registered cloud a table of section 5.2 (5.5, 5.6) was computed on."""

    terrain: str
    frames: int
    points: int


#: Case of every terrain of chapter 4: "nav" (urban navigation, 3D) or "lan" (landing, 2D),
#: as its name says (``sim_nav_1``); a test checks it against each terrain's own spec.
TERRAIN_CASE: dict[str, str] = {name: name.split("_")[1] for name in TERRAINS}

#: Mappers the thesis applied per case (chapter 4 and tables 5.1-5.4).
CASE_MAPPERS: dict[str, tuple[str, str]] = {"nav": ("octomap", "alte3d"),
                                            "lan": ("quadtree", "alte2d")}

_NAV_SIM: dict[str, MapperParams] = {"octomap": {"resolution": 5.0},
            "alte3d": {"max_res": 6, "min_pts": 10, "min_pts_split": 20}}
_NAV_EXP: dict[str, MapperParams] = {"octomap": {"resolution": 10.0},
            "alte3d": {"max_res": 5, "min_pts": 5, "min_pts_split": 10}}
_ALTE2D: MapperParams = {"kappa": 0.1, "max_res": 6, "min_pts": 10}

#: Chapter 4 parameters per terrain and mapper (sections 4.1.1-4.2.4).
CH4_PARAMS: dict[str, dict[str, MapperParams]] = {
    "sim_nav_1": _NAV_SIM, "sim_nav_2": _NAV_SIM,
    "sim_lan_1": {"quadtree": {"max_points": 200}, "alte2d": _ALTE2D},
    "sim_lan_2": {"quadtree": {"max_points": 25}, "alte2d": _ALTE2D},
    "exp_nav_1": _NAV_EXP, "exp_nav_2": _NAV_EXP,
    "exp_lan_1": {"quadtree": {"max_points": 200}, "alte2d": _ALTE2D},
    "exp_lan_2": {"quadtree": {"max_points": 200}, "alte2d": _ALTE2D},
}

#: Tables 5.5 and 5.6: frames and points of the registered clouds analysed in 5.2.
POINT_CLOUDS: dict[int, PointCloudRef] = {
    5: {"terrain": "sim_nav_1", "frames": 569, "points": 381187},
    6: {"terrain": "sim_lan_2", "frames": 508, "points": 439032},
}

#: Tables 5.7, 5.8, 5.9, 5.12: (params, elapsed s, basis functions, HD m, MHD m) per row.
SWEEPS: dict[int, Sweep] = {
    7: {"mapper": "quadtree", "terrain": "sim_lan_2", "rows": [
        ({"max_points": 25}, 43.38, 24343, 5.515, 1.235),
        ({"max_points": 100}, 5.51, 7048, 5.310, 1.029),
        ({"max_points": 150}, 3.06, 4399, 5.308, 1.090),
        ({"max_points": 200}, 2.08, 3565, 5.310, 1.206),
        ({"max_points": 500}, 1.02, 1375, 5.311, 1.290),
        ({"max_points": 1000}, 0.62, 757, 5.106, 1.168)]},
    8: {"mapper": "octomap", "terrain": "sim_nav_1", "rows": [
        ({"resolution": 1.0}, 3.24, 969, 5.0070, 1.2499),
        ({"resolution": 2.0}, 6.96, 5499, 4.9430, 1.0236),
        ({"resolution": 3.0}, 9.92, 16423, 3.9773, 0.4301),
        ({"resolution": 4.0}, 13.82, 35877, 2.5772, 0.3760),
        ({"resolution": 5.0}, 19.34, 65750, 3.0499, 0.3702),
        ({"resolution": 6.0}, 24.61, 108607, 2.9875, 0.4049)]},
    9: {"mapper": "alte2d", "terrain": "sim_lan_2", "rows": [
        ({"kappa": 0.1, "max_res": 4, "min_pts": 100}, 3.1455, 216, 5.1050, 0.8496),
        ({"kappa": 1.0, "max_res": 5, "min_pts": 10}, 4.45, 664, 5.1050, 0.7250),
        ({"kappa": 0.1, "max_res": 6, "min_pts": 10}, 4.9348, 2136, 5.1050, 0.8256),
        ({"kappa": 0.05, "max_res": 4, "min_pts": 100}, 3.18, 220, 5.1050, 0.8496),
        ({"kappa": 0.01, "max_res": 5, "min_pts": 100}, 3.51, 668, 5.1050, 0.7250),
        ({"kappa": 0.01, "max_res": 6, "min_pts": 10}, 4.30, 2176, 5.1050, 0.8258)]},
    12: {"mapper": "alte3d", "terrain": "sim_nav_1", "rows": [
        ({"min_pts": 20, "min_pts_split": 10, "max_res": 6}, 29.72, 15273, 2.3751, 0.3177),
        ({"min_pts": 20, "min_pts_split": 10, "max_res": 4}, 6.89, 1137, 1.9756, 0.5684),
        ({"min_pts": 5, "min_pts_split": 10, "max_res": 5}, 11.59, 4249, 1.9112, 0.3688),
        ({"min_pts": 20, "min_pts_split": 40, "max_res": 6}, 66.88, 12321, 1.9162, 0.2361),
        ({"min_pts": 20, "min_pts_split": 40, "max_res": 4}, 10.45, 1065, 4.3339, 0.5606),
        ({"min_pts": 40, "min_pts_split": 10, "max_res": 5}, 11.5, 4249, 5.9167, 0.3420)]},
}

#: Tables 5.10 and 5.11: the thesis' chosen best map per mapper (row index into SWEEPS).
COMPARISONS: dict[int, dict[str, tuple[int, int]]] = {
    10: {"quadtree": (7, 2), "alte2d": (9, 3)},
    11: {"octomap": (8, 2), "alte3d": (12, 2)},
}

#: Tables 5.1-5.4: qualitative findings (High/Mid/Low, Yes/No) per mapper and criterion.
QUALITATIVE: dict[int, dict[str, dict[str, str]]] = {
    1: {"quadtree": {"adaptability": "Mid", "robustness": "Low", "development": "Low",
                     "recursiveness": "No", "outlier_rejection": "High"},
        "alte2d": {"adaptability": "High", "robustness": "Mid", "development": "Mid",
                   "recursiveness": "Yes", "outlier_rejection": "Mid"}},
    2: {"octomap": {"adaptability": "Low", "robustness": "High", "development": "High",
                    "recursiveness": "Yes", "outlier_rejection": "High"},
        "alte3d": {"adaptability": "High", "robustness": "Low", "development": "Low",
                   "recursiveness": "Yes", "outlier_rejection": "Mid"}},
    3: {"quadtree": {"obstacle_identification": "Mid", "outlier_rejection": "High",
                     "map_quality": "Mid"},
        "alte2d": {"obstacle_identification": "High", "outlier_rejection": "Mid",
                   "map_quality": "High"}},
    4: {"octomap": {"map_size": "High", "free_space_mapping": "Yes",
                    "overhanging_structures": "Yes"},
        "alte3d": {"map_size": "Mid", "free_space_mapping": "No",
                   "overhanging_structures": "Yes"}},
}


def mapper_params(terrain: str) -> dict[str, MapperParams]:
    """The chapter 4 parameters of ``terrain``'s two mappers (copies, safe to modify)."""
    try:
        return {name: dict(p) for name, p in CH4_PARAMS[terrain].items()}
    except KeyError as err:
        raise ParameterError(
            f"terrain {terrain!r} has no chapter 4 parameters; known: {', '.join(CH4_PARAMS)}"
        ) from err


def sweep_table(number: int) -> pd.DataFrame:
    """Table 5.``number`` (7, 8, 9 or 12) with one column per parameter and ``thesis_*``."""
    if number not in SWEEPS:
        raise ParameterError(f"table 5.{number} is not a sweep; sweeps: {sorted(SWEEPS)}")
    spec = SWEEPS[number]
    rows = [{"mapper": spec["mapper"], "terrain": spec["terrain"], **params,
             "thesis_elapsed_s": t, "thesis_basis_functions": bf, "thesis_hd_m": hd,
             "thesis_mhd_m": mhd}
            for params, t, bf, hd, mhd in spec["rows"]]
    return pd.DataFrame(rows)


def qualitative_table(number: int) -> pd.DataFrame:
    """Table 5.``number`` (1-4): one row per mapper, one column per criterion."""
    if number not in QUALITATIVE:
        raise ParameterError(f"table 5.{number} is not qualitative; those are 1-4")
    return pd.DataFrame.from_dict(QUALITATIVE[number], orient="index").rename_axis("mapper")
