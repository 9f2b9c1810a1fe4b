"""The thesis' questions, and which one each claim bears on.

The front page groups the claims by the question a reader brings (:data:`QUESTIONS`,
in page order) instead of listing them flat. :func:`question` reads it off the claim's
check: comparisons of the landing pair (Quadtree, 2D-ALTE) or of the navigation pair
(Octomap, 3D-ALTE), or of both; how a mapper responds to its parameters (trends,
effects, optima, the spread of its metric over its settings, an ablation contrast);
whether the thesis' metric tracks the truth; and judgements no map measures (design
properties, code maturity).
"""

from __future__ import annotations

from alte.lab.studies.thesis.claims.types import (
    Agreement,
    AllOf,
    Check,
    Claim,
    Compare,
    Contrast,
    Effect,
    NotMeasurable,
    Optimum,
    Property,
    Summary,
    Trend,
)

__all__ = ["QUESTIONS", "question"]

#: Question id -> the question, in page order.
QUESTIONS: dict[str, str] = {
    "landing": "Landing: are 2D-ALTE's maps better than Quadtree's?",
    "navigation": "Urban navigation: are 3D-ALTE's maps better than Octomap's?",
    "both": "Both cases: do the adaptive maps beat their counterparts overall?",
    "parameters": "How does each mapper respond to its parameters?",
    "metric": "Can the thesis' metric (HD, MHD) be trusted?",
    "design": "Design and maturity: judgements no map measures",
}
_CASES = {"lan": "landing", "nav": "navigation"}


def _is_metric(part: Check) -> bool:
    return isinstance(part, Agreement) or (
        isinstance(part, Trend) and part.x == "basis_functions"
        and part.metric in ("mhd_m", "hd_m"))


def _is_parameter(part: Check) -> bool:
    return isinstance(part, Trend | Effect | Optimum | Contrast) or (
        isinstance(part, Summary) and part.agg == "cv")


def question(claim: Claim) -> str:
    """The id (a key of :data:`QUESTIONS`) of the question ``claim`` bears on."""
    parts = claim.check.parts if isinstance(claim.check, AllOf) else (claim.check,)
    if all(isinstance(p, NotMeasurable | Property) for p in parts):
        return "design"
    if any(_is_metric(p) for p in parts):
        return "metric"
    if any(isinstance(p, Contrast) for p in parts) or all(_is_parameter(p) for p in parts):
        return "parameters"
    cases = {p.case for p in parts if isinstance(p, Compare | Summary)}
    return _CASES[cases.pop()] if len(cases) == 1 else "both"
