"""The comparative claims of thesis chapter 6 (Conclusions), quoted verbatim."""

from __future__ import annotations

from alte.lab.studies.thesis.claims.types import (
    Agreement,
    AllOf,
    Claim,
    Compare,
    Contrast,
    Summary,
    Trend,
)

__all__ = ["CH6_CLAIMS"]

_S = "6"


def _at_size(case: str, better: str, other: str, metric: str = "mhd_m",
             higher: bool = False) -> Compare:
    return Compare(case, better, other, metric, "equal_size", higher_is_better=higher)


def _at_fidelity(case: str, better: str, other: str, metric: str = "basis_functions") -> Compare:
    return Compare(case, better, other, metric, "equal_fidelity")


_NAV_STRENGTHS = AllOf((
    _at_fidelity("nav", "octomap", "alte3d", "elapsed_s"),
    Summary("nav", "octomap", "mhd_m", "cv", "alte3d"),
    Summary("nav", "alte3d", "size_octaves", "median", "octomap", higher_is_better=True),
))
_NAV_READING = ("efficiency: mapping time for the same MHD; robustness: coefficient of "
                "variation of MHD over the settings; adaptability: cell-size octaves")
_HD_VS_MHD = AllOf((
    Agreement("lan", "quadtree", "mhd_m", "height_rmse_m", other="hd_m"),
    Agreement("lan", "alte2d", "mhd_m", "height_rmse_m", other="hd_m"),
    Agreement("nav", "octomap", "mhd_m", "accuracy_mean_m", other="hd_m"),
    Agreement("nav", "alte3d", "mhd_m", "accuracy_mean_m", other="hd_m"),
))
_OVERALL = AllOf((_at_size("lan", "alte2d", "quadtree"), _at_fidelity("lan", "alte2d", "quadtree"),
                  _at_size("nav", "alte3d", "octomap"), _at_fidelity("nav", "alte3d", "octomap")))

#: Every comparative claim of chapter 6, in the thesis' order.
CH6_CLAIMS: tuple[Claim, ...] = (
    Claim("6-landing-reliable", _S,
          "Focusing on autonomous landing, Quadtree has potential applications in simple "
          "missions that do not require scan integration, whereas 2D-ALTE is a much more "
          "reliable mapping algorithm for a broader spectrum of conditions.",
          AllOf((_at_size("lan", "alte2d", "quadtree", "height_rmse_m"),
                 _at_size("lan", "alte2d", "quadtree", "completeness", higher=True),
                 _at_size("lan", "alte2d", "quadtree", "obstacle_recall", higher=True),
                 _at_size("lan", "alte2d", "quadtree", "obstacle_precision", higher=True))),
          "more reliable over a broader spectrum: lower true height RMSE, higher "
          "completeness, and more of the true obstacles shown with fewer that are not "
          "there (obstacle recall and precision), at equal size on every landing terrain"),
    Claim("6-octomap-strengths", _S,
          "For example, Octomap is far superior in terms of efficiency and robustness but "
          "fails to adapt to variations in point densities.",
          _NAV_STRENGTHS, _NAV_READING),
    Claim("6-alte3d-weaknesses", _S,
          "In contrast, 3D-ALTE excels in adaptability but currently lacks robustness and "
          "overall code efficiency.",
          _NAV_STRENGTHS, _NAV_READING),
    Claim("6-free-space-memory", _S,
          "Only Octomap models free space, but this causes the resulting maps to require "
          "significant memory, making them nonviable for urban navigation missions.",
          AllOf((Summary("nav", "octomap", "free_share", "median", higher_is_better=True,
                         threshold=0.5),
                 _at_fidelity("nav", "alte3d", "octomap", "memory_bytes"))),
          "free cells are most of Octomap's basis functions and Octomap needs more memory "
          "than 3D-ALTE for the same MHD; 'nonviable' is a judgement and is not tested"),
    Claim("6-alte3d-lightweight", _S,
          "In contrast, 3D-ALTE's multi-resolution grids create lightweight maps that are "
          "feasible for use although they lack free-space mapping.",
          AllOf((_at_fidelity("nav", "alte3d", "octomap", "memory_bytes"),
                 _at_fidelity("nav", "alte3d", "octomap"))),
          "lightweight: less memory and fewer basis functions for the same MHD"),
    Claim("6-hd-inconsistent", _S,
          "It was found that the Hausdorff Distance is inconsistent in the presence of "
          "outliers, so a modified version was used instead, the Modified Hausdorff Distance.",
          _HD_VS_MHD,
          "over each mapper's settings MHD tracks the true error (height RMSE in 2D, "
          "mean accuracy in 3D) better than HD"),
    Claim("6-mhd-unreliable", _S,
          "However, the MHD became non-reliable when analyzing maps with a high number of "
          "basis functions.",
          AllOf(tuple(Trend(case, mapper, "basis_functions", "mhd_m", +1, largest_half=True)
                      for case, mapper in (("lan", "quadtree"), ("lan", "alte2d"),
                                           ("nav", "octomap"), ("nav", "alte3d")))),
          "over the larger half of each mapper's maps MHD rises with basis functions"),
    Claim("6-quadtree-worse", _S,
          "The numbers show that Quadtree produces less reliable maps that are computationally "
          "heavier and take longer to produce than 2D-ALTE's maps.",
          AllOf((_at_size("lan", "alte2d", "quadtree"),
                 _at_fidelity("lan", "alte2d", "quadtree"),
                 _at_fidelity("lan", "alte2d", "quadtree", "elapsed_s"))),
          "less reliable: higher MHD at equal size; heavier: more basis functions, and "
          "longer: more time, for the same MHD"),
    Claim("6-alte2d-all-metrics", _S,
          "Except for outlier rejection, 2D-ALTE outperforms Quadtree in all the proposed "
          "metrics.",
          AllOf((_at_fidelity("lan", "alte2d", "quadtree", "elapsed_s"),
                 _at_fidelity("lan", "alte2d", "quadtree"),
                 _at_size("lan", "alte2d", "quadtree"),
                 _at_size("lan", "quadtree", "alte2d", "hd_minus_mhd_m"))),
          "time and basis functions for the same MHD, MHD at equal size; and Quadtree's "
          "smaller HD - MHD at equal size (the exception)"),
    Claim("6-3d-tradeoff", _S,
          "In the 3D case, Octomap is much more efficient processing data than 3D-ALTE but "
          "generates large maps that impose high computational loads, whereas 3D-ALTE is "
          "slower but produces better maps in terms of memory requirements.",
          AllOf((_at_fidelity("nav", "octomap", "alte3d", "elapsed_s"),
                 _at_fidelity("nav", "alte3d", "octomap"),
                 _at_fidelity("nav", "alte3d", "octomap", "memory_bytes"))),
          "all for the same MHD: time (Octomap faster), basis functions and memory (3D-ALTE "
          "smaller)"),
    Claim("6-3d-undecided", _S,
          "Still, it is not possible to determine which one is better due to the "
          "inconsistencies in MHD related to the number of basis functions.",
          AllOf(tuple(Compare("nav", "alte3d", "octomap", metric, "equal_size",
                              higher_is_better=higher, relation="undecided")
                      for metric, higher in (("accuracy_mean_m", False),
                                             ("completeness", True)))),
          "with ground truth it is testable: the claim holds only where neither map is "
          "better, beyond its interval, in true accuracy and completeness at equal size"),
    Claim("6-alte3d-sensitive", _S, "3D-ALTE is currently very sensitive to tuning parameters.",
          Summary("nav", "octomap", "mhd_m", "cv", "alte3d"),
          "read against Octomap: a larger coefficient of variation of MHD over the settings"),
    Claim("6-occupancy-level", _S,
          "However, the analysis showed that this solution is still not robust enough.",
          AllOf((Contrast("nav", "alte3d", "mhd_m", "cv", "min_pts_per_leaf"),
                 Summary("nav", "octomap", "mhd_m", "cv", "alte3d"))),
          "the solution is the tree-level occupancy criterion (min_pts as a density set at "
          "level 6, the grid as specified), read against a plain count per leaf (the "
          "min_pts_per_leaf ablation): it makes 3D-ALTE less sensitive to its settings (a "
          "smaller coefficient of variation of MHD over them: solved in part), yet more "
          "sensitive than Octomap (not robust enough)"),
    Claim("6-overall", _S,
          "Overall, the ALTE approaches compare favorably to powerful algorithms like Octomap "
          "and Quadtree, and should be considered for real-time applications.",
          _OVERALL,
          "ahead of the counterpart's curve, lower MHD at equal size and fewer "
          "basis functions at equal MHD, in both cases; 'should be considered' is advice"),
)
