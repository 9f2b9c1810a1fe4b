"""The comparative claims of thesis chapter 5, quoted verbatim with their sections.

Table claims (5.1-5.4) quote the two table cells compared; every other quote is a
verbatim sentence (or clause) of the thesis text.
"""

from __future__ import annotations

from alte.lab.studies.thesis.claims.types import (
    Agreement,
    AllOf,
    Claim,
    Compare,
    Effect,
    NotMeasurable,
    Optimum,
    Property,
    Summary,
    Trend,
    Where,
)

__all__ = ["CH5_CLAIMS", "views"]


def views(case: str, better: str, other: str, metric: str, curve: Where, *,
          factor: float = 1.0) -> AllOf:
    """The thesis' operating point, the thesis' rule on our sweep, and the curves."""
    ats: tuple[Where, ...] = ("thesis_point", "rule", curve)
    return AllOf(tuple(Compare(case, better, other, metric, at, factor=factor) for at in ats))


def _size(case: str, better: str, other: str, metric: str = "basis_functions") -> Compare:
    return Compare(case, better, other, metric, "equal_fidelity")


def _fidelity(case: str, better: str, other: str, metric: str = "mhd_m",
              higher: bool = False) -> Compare:
    return Compare(case, better, other, metric, "equal_size", higher_is_better=higher)


#: Obstacle identification at equal size: the share of the true obstacles the map shows
#: and the share of its obstacles that are there (:mod:`alte.lab.studies.obstacles`).
_OBSTACLES = AllOf((_fidelity("lan", "alte2d", "quadtree", "obstacle_recall", higher=True),
                    _fidelity("lan", "alte2d", "quadtree", "obstacle_precision", higher=True)))
_OBSTACLE_READING = ("obstacle identification read as recall (the share of the simulator's "
                     "objects standing at least the landing study's obstacle step above the "
                     "ground, seen from above, that the map shows as obstacles) and precision "
                     "(the share of the map's obstacles that are there), at equal size")
_ADAPT = "cell-size octaves log2(largest/smallest cell edge), median over the settings"
_ROBUST = ("robustness read as a small coefficient of variation of MHD over the mapper's "
           "settings (it depends on the ranges swept)")

_TABLES: tuple[Claim, ...] = (
    Claim("t5.1-adaptability", "5.1, table 5.1",
          "Adaptability: Quadtree Mid, 2D ALTE High",
          Summary("lan", "alte2d", "size_octaves", "median", "quadtree", higher_is_better=True),
          _ADAPT),
    Claim("t5.1-robustness", "5.1, table 5.1", "Robustness: Quadtree Low, 2D ALTE Mid",
          Summary("lan", "alte2d", "mhd_m", "cv", "quadtree"), _ROBUST),
    Claim("t5.1-development", "5.1, table 5.1", "Development: Quadtree Low, 2D ALTE Mid",
          NotMeasurable("the level of development is a judgement of code maturity, not a "
                        "property of a map")),
    Claim("t5.1-recursiveness", "5.1, table 5.1",
          "Recursiveness: Quadtree No, 2D ALTE Yes",
          Property("incremental", ("alte2d",), ("quadtree",)),
          "checked on our implementations (the mappers' incremental attribute)"),
    Claim("t5.1-outliers", "5.1, table 5.1",
          "Outlier Rejection: Quadtree High, 2D ALTE Mid",
          _fidelity("lan", "quadtree", "alte2d", "hd_minus_mhd_m"),
          "outlier rejection read as a smaller HD - MHD (thesis 5.2.2) at equal size"),
    Claim("t5.2-adaptability", "5.1, table 5.2", "Adaptability: Octomap Low, 3D ALTE High",
          Summary("nav", "alte3d", "size_octaves", "median", "octomap", higher_is_better=True),
          _ADAPT),
    Claim("t5.2-robustness", "5.1, table 5.2", "Robustness: Octomap High, 3D ALTE Low",
          Summary("nav", "octomap", "mhd_m", "cv", "alte3d"), _ROBUST),
    Claim("t5.2-development", "5.1, table 5.2", "Development: Octomap High, 3D ALTE Low",
          NotMeasurable("the level of development is a judgement of code maturity, not a "
                        "property of a map")),
    Claim("t5.2-outliers", "5.1, table 5.2",
          "Outlier Rejection: Octomap High, 3D ALTE Mid",
          _fidelity("nav", "octomap", "alte3d", "hd_minus_mhd_m"),
          "outlier rejection read as a smaller HD - MHD at equal size"),
    Claim("t5.3-obstacles", "5.1, table 5.3",
          "Obstacle Identification: Quadtree Mid, 2D ALTE High",
          _OBSTACLES, _OBSTACLE_READING),
    Claim("t5.3-outliers", "5.1, table 5.3", "Outlier rejection: Quadtree High, 2D ALTE Mid",
          _fidelity("lan", "quadtree", "alte2d", "hd_minus_mhd_m"),
          "outlier rejection read as a smaller HD - MHD at equal size"),
    Claim("t5.3-quality", "5.1, table 5.3", "Map Quality: Quadtree Mid, 2D ALTE High",
          AllOf((_fidelity("lan", "alte2d", "quadtree", "height_rmse_m"),
                 _fidelity("lan", "alte2d", "quadtree", "completeness", higher=True))),
          "map quality read as the true height RMSE and completeness at equal size"),
    Claim("t5.4-size", "5.1, table 5.4", "Map Size: Octomap High, 3D ALTE Mid",
          _size("nav", "alte3d", "octomap"),
          "map size read as basis functions needed for the same MHD"),
    Claim("t5.4-free-space", "5.1, table 5.4",
          "Free Space Mapping: Octomap Yes, 3D ALTE No",
          NotMeasurable("a design property: Octomap stores observed-free leaves, 3D-ALTE's "
                        "empty leaves mean not occupied, not observed free; whether the free "
                        "leaves are truly free is free_truly_free_share (Octomap only)")),
)

_REMARKS: tuple[Claim, ...] = (
    Claim("5.1.1-octomap-load", "5.1.1 (Octomap)",
          "However, its high computational demands restrict its usage, especially on UAVs, "
          "where the processing power is relatively limited.",
          Compare("nav", "alte3d", "octomap", "elapsed_s", "equal_fidelity"),
          "high demands read against 3D-ALTE: more mapping time for the same MHD"),
    Claim("5.1.1-octomap-size", "5.1.1 (Octomap)",
          "The lack of adaptability in the mapping process also plays a considerable role as "
          "it highly contributes to the map's size.",
          _size("nav", "alte3d", "octomap"),
          "Octomap needs more basis functions than 3D-ALTE for the same MHD"),
    Claim("5.1.1-octomap-fidelity", "5.1.1 (Octomap)",
          "This algorithm outperforms every other mapping technique in all areas except for "
          "the already mentioned computational burden and adaptability (multiresolution).",
          AllOf((_fidelity("nav", "octomap", "alte3d"),
                 _fidelity("nav", "octomap", "alte3d", "accuracy_mean_m"),
                 _fidelity("nav", "octomap", "alte3d", "completeness", higher=True))),
          "the areas read as fidelity at equal size: MHD, true accuracy and completeness"),
    Claim("5.1.1-alte2d-superior", "5.1.1 (2D-ALTE)",
          "Thus, considering its level of development, 2D-ALTE has a superior performance.",
          NotMeasurable("performance weighed by the level of development; development is not "
                        "measured (the measurable comparisons are claims 5.2.2 and 6)")),
    Claim("5.1.1-alte2d-landing", "5.1.1 (2D-ALTE)",
          "Concerning autonomous landing, 2D-ALTE excels in the most critical matters: "
          "obstacle identification and map quality.",
          AllOf((*_OBSTACLES.parts, _fidelity("lan", "alte2d", "quadtree", "height_rmse_m"),
                 _fidelity("lan", "alte2d", "quadtree", "completeness", higher=True))),
          "obstacle identification (recall and precision against the simulator's objects, "
          "as in t5.3-obstacles) and map quality (true height RMSE, completeness), all at "
          "equal size"),
    Claim("5.1.1-alte3d-advantage", "5.1.1 (3D-ALTE)",
          "The ability to analyze space using variable-sized grids gives this algorithm a "
          "significant advantage over Octomap.",
          _size("nav", "alte3d", "octomap"),
          "the advantage read as fewer basis functions for the same MHD"),
    Claim("5.1.1-alte3d-compact", "5.1.1 (3D-ALTE)",
          "In the context of urban navigation, 3D-ALTE generates compact terrain "
          "representations that do not impose high computational loads.",
          AllOf((_size("nav", "alte3d", "octomap", "memory_bytes"),
                 _size("nav", "alte3d", "octomap"))),
          "compact: less memory; load on a planner: fewer basis functions (5.2.1), both "
          "for the same MHD as Octomap"),
    Claim("5.1.1-free-space-size", "5.1.1 (3D-ALTE)",
          "It appears that not discriminating vacant from unknown space has a drastic impact "
          "on the algorithm's processing requirements.",
          Summary("nav", "octomap", "free_share", "median", higher_is_better=True,
                  threshold=0.5),
          "free cells are most (> 50 %) of Octomap's basis functions"),
)

_LAN, _NAV = "lan", "nav"
_RESULTS: tuple[Claim, ...] = (
    Claim("5.2.2-quadtree-growth", "5.2.2 (Quadtree)",
          "This iterative process produces an exponential growth in execution time and basis "
          "functions when decreasing the threshold.",
          AllOf((Trend(_LAN, "quadtree", "max_points", "elapsed_s", -1),
                 Trend(_LAN, "quadtree", "max_points", "basis_functions", -1))),
          "growth read as a falling rank trend with max_points (the shape is not tested)"),
    Claim("5.2.2-quadtree-optimum", "5.2.2 (Quadtree)",
          "The accuracy of the map increases with the resolution to a certain point.",
          Optimum(_LAN, "quadtree", "max_points", "mhd_m", "low"),
          "the finest setting (smallest max_points) has a higher MHD than the best "
          "coarser one"),
    Claim("5.2.2-quadtree-mhd", "5.2.2 (Quadtree)",
          "The MHD is inversely proportional to Max pts per cell, which means the mismatch "
          "levels increase as the resolutions become lower.",
          Trend(_LAN, "quadtree", "max_points", "mhd_m", +1),
          "follows the explanation (MHD rises as max_points rises, the map coarsens); "
          "'inversely proportional' says the opposite and is read as a slip"),
    Claim("5.2.2-quadtree-hd", "5.2.2 (Quadtree)",
          "The HD metric fails to deliver conclusive results due to the presence of outliers.",
          Agreement(_LAN, "quadtree", "mhd_m", "height_rmse_m", other="hd_m"),
          "over Quadtree's settings MHD tracks the true height RMSE better than HD"),
    Claim("5.2.2-octomap-cost", "5.2.2 (Octomap)",
          "Elapsed time and basis functions are inversely proportional to the size of the "
          "cell.",
          AllOf((Trend(_NAV, "octomap", "resolution", "elapsed_s", +1),
                 Trend(_NAV, "octomap", "resolution", "basis_functions", +1))),
          "both rise with resolution (cells per metre)"),
    Claim("5.2.2-octomap-error", "5.2.2 (Octomap)",
          "HD and MHD also seem inversely proportional except in the last map (Resolution: 6).",
          AllOf((Trend(_NAV, "octomap", "resolution", "hd_m", -1),
                 Trend(_NAV, "octomap", "resolution", "mhd_m", -1))),
          "both fall as the resolution rises (rank trend over the whole grid)"),
    Claim("5.2.2-octomap-unreliable", "5.2.2 (Octomap)",
          "It means that the Hausdorff approaches, implemented as proposed in this thesis, "
          "become more unreliable as the number of basis functions increases.",
          Trend(_NAV, "octomap", "basis_functions", "mhd_m", +1, largest_half=True),
          "over the larger half of Octomap's maps MHD rises with basis functions"),
    Claim("5.2.2-alte2d-time", "5.2.2 (2D-ALTE)",
          "Kappa seems to be closely related to the algorithm's execution time but Max Res is "
          "more heavily correlated.",
          Effect(_LAN, "alte2d", "elapsed_s", "max_res", other="kappa")),
    Claim("5.2.2-alte2d-size", "5.2.2 (2D-ALTE)",
          "The number of basis functions also depends on these two parameters, but it appears "
          "that Max Res is the defining factor.",
          Effect(_LAN, "alte2d", "basis_functions", "max_res", other="kappa")),
    Claim("5.2.2-alte2d-unreliable", "5.2.2 (2D-ALTE)",
          "Again, HD and MHD results are unreliable for higher resolutions.",
          Trend(_LAN, "alte2d", "basis_functions", "mhd_m", +1, largest_half=True),
          "over the larger half of 2D-ALTE's maps MHD rises with basis functions"),
    Claim("5.2.2-alte3d-drivers", "5.2.2 (3D-ALTE)",
          "MAX RES appears to be the driving factor in both execution time and number of basis "
          "functions. MIN PTS 2 also influences these metrics but to a lesser degree.",
          AllOf((Effect(_NAV, "alte3d", "elapsed_s", "max_res", other="min_pts_split"),
                 Effect(_NAV, "alte3d", "basis_functions", "max_res", other="min_pts_split")))),
    Claim("5.2.2-alte3d-min-pts", "5.2.2 (3D-ALTE)",
          "MIN PTS has no considerable effect due to it being an occupancy criteria that has "
          "no effect on the division process.",
          AllOf((Effect(_NAV, "alte3d", "elapsed_s", "min_pts", max_spread=0.1),
                 Effect(_NAV, "alte3d", "basis_functions", "min_pts", max_spread=0.1))),
          "no considerable effect: the means over min_pts levels span < 10 % of the mean"),
    Claim("5.2.2-alte3d-incomplete", "5.2.2 (3D-ALTE)",
          "Resolutions of (4) produce an incomplete map due the occupancy criterion added to "
          "refine the mapping process.",
          Trend(_NAV, "alte3d", "max_res", "completeness", +1),
          "completeness rises with max_res"),
    Claim("5.2.2-alte3d-insensitive", "5.2.2 (3D-ALTE)",
          "This implies that the Hausdorff metrics are not sensitive enough to missing "
          "information.",
          Agreement(_NAV, "alte3d", "mhd_m", "completeness", sign=-1),
          "over 3D-ALTE's settings MHD does not track (rho <= 0.5) the loss of "
          "completeness"),
)

_COMPARISON: tuple[Claim, ...] = (
    Claim("5.2.2-2d-time", "5.2.2 (Comparison)",
          "the elapsed time in both cases is almost the same",
          AllOf(tuple(Compare(_LAN, "alte2d", "quadtree", "elapsed_s", at, relation="similar")
                      for at in ("thesis_point", "rule"))),
          "almost the same: the time ratio lies within 1 +/- 25 %"),
    Claim("5.2.2-2d-size", "5.2.2 (Comparison)",
          "but ALTE has twenty times fewer basis functions",
          views(_LAN, "alte2d", "quadtree", "basis_functions", "equal_fidelity", factor=20.0),
          "twenty times: Quadtree/2D-ALTE basis functions >= 20 (the thesis' 4399/220)"),
    Claim("5.2.2-2d-mhd", "5.2.2 (Comparison)", "and a better map in terms of MHD",
          views(_LAN, "alte2d", "quadtree", "mhd_m", "equal_size")),
    Claim("5.2.2-2d-outliers", "5.2.2 (Comparison)",
          "The difference between HD and MHD shows that Quadtree is better for outlier "
          "rejection, which agrees with the qualitative observations.",
          views(_LAN, "quadtree", "alte2d", "hd_minus_mhd_m", "equal_size")),
    Claim("5.2.2-3d-time", "5.2.2 (Comparison)",
          "Octomap's elapsed time is better, which means Octomap is much more efficient in "
          "analyzing data.",
          views(_NAV, "octomap", "alte3d", "elapsed_s", "equal_fidelity")),
    Claim("5.2.2-3d-size", "5.2.2 (Comparison)",
          "However, the resulting number of basis functions is almost four times ALTE's "
          "number.",
          views(_NAV, "alte3d", "octomap", "basis_functions", "equal_fidelity", factor=3.5),
          "almost four times: Octomap/3D-ALTE basis functions >= 3.5 (the thesis' 3.9)"),
    Claim("5.2.2-3d-mhd", "5.2.2 (Comparison)",
          "The MHD metric shows that ALTE generates more accurate maps",
          views(_NAV, "alte3d", "octomap", "mhd_m", "equal_size")),
    Claim("5.2.2-3d-outliers", "5.2.2 (Comparison)",
          "ALTE is better at rejecting outliers due to the additional occupancy criterion "
          "implemented in this thesis.",
          views(_NAV, "alte3d", "octomap", "hd_minus_mhd_m", "equal_size")),
    Claim("5.2.2-overall", "5.2.2 (Comparison)",
          "Overall, the ALTE algorithms have an excellent performance when compared to their "
          "counterparts.",
          AllOf((_fidelity(_LAN, "alte2d", "quadtree"), _size(_LAN, "alte2d", "quadtree"),
                 _fidelity(_NAV, "alte3d", "octomap"), _size(_NAV, "alte3d", "octomap"))),
          "ahead of the counterpart's curve, lower MHD at equal size and fewer basis "
          "functions at equal MHD, in both cases"),
    Claim("5.2.2-2d-superior", "5.2.2 (Comparison)",
          "The 2D version is clearly superior in terms of efficiency and map accuracy",
          AllOf((Compare(_LAN, "alte2d", "quadtree", "elapsed_s", "equal_fidelity"),
                 _fidelity(_LAN, "alte2d", "quadtree"),
                 _fidelity(_LAN, "alte2d", "quadtree", "height_rmse_m"))),
          "efficiency: mapping time for the same MHD; accuracy: MHD and true height RMSE at "
          "equal size"),
    Claim("5.2.2-3d-size-better", "5.2.2 (Comparison)",
          "the 3D version is better in critical aspects such as map size",
          _size(_NAV, "alte3d", "octomap")),
)

#: Every comparative claim of chapter 5, in the thesis' order.
CH5_CLAIMS: tuple[Claim, ...] = _TABLES + _REMARKS + _RESULTS + _COMPARISON
