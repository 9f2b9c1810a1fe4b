"""Typed, machine-checkable formulations of the thesis' comparative claims.

A :class:`Claim` quotes the thesis (text and section) and carries one check, a typed
record saying what to measure in the trade-off table (see :mod:`alte.lab.studies.analysis.tradeoff`)
and which sign of the measured statistic supports the claim. Every check is evaluated
per terrain of its case (``"lan"``: landing, 2D maps; ``"nav"``: navigation, 3D maps)
and per simulation seed; :mod:`alte.lab.studies.analysis.evidence` turns the per-seed statistics
into bootstrap intervals and a verdict.

Kinds of check:

* :class:`Compare`: mapper ``better`` beats ``other`` on ``metric``, read at the thesis'
  chosen parameters (``at="thesis_point"``), at the row the thesis' rule picks from our
  sweep (``"rule"``), at equal map size read off the Pareto fronts (``"equal_size"``) or,
  for a size/time ``metric``, at equal fidelity (``"equal_fidelity"``);
* :class:`Trend`: ``metric`` rises (``sign=+1``) or falls with ``x`` within one mapper;
* :class:`Optimum`: ``metric`` is best at an interior setting of ``x``, not the finest;
* :class:`Effect`: parameter ``param`` moves ``metric`` more than ``other`` does, or
  (``max_spread``) hardly at all;
* :class:`Agreement`: ``metric`` tracks a ground-truth ``reference`` (better than
  ``other``, or not beyond ``min_rho``);
* :class:`Summary`: an aggregate of ``column`` over a mapper's settings (median,
  coefficient of variation) compared between two mappers or against a threshold;
* :class:`Contrast`: the same aggregate in the base grid and in an ablation variant
  (one thing changed), e.g. with and without 3D-ALTE's tree-level occupancy criterion;
* :class:`Property`: a class attribute of the mapper implementations;
* :class:`AllOf`: a conjunction (a quote making several comparisons);
* :class:`NotMeasurable`: no map metric can decide it; the reason says why.
"""

from __future__ import annotations

from dataclasses import dataclass, fields, replace
from typing import Literal

__all__ = ["CASES", "SIZE_COLUMNS", "Agreement", "AllOf", "Check", "Claim", "Compare",
           "Contrast", "Effect", "NotMeasurable", "Optimum", "Property", "Relation", "Summary",
           "Trend", "Where", "renamed"]

#: Terrain cases: landing (2D maps) and urban navigation (3D maps).
CASES = ("lan", "nav")
#: Columns measuring map size (the x axis of the trade-off curves).
SIZE_COLUMNS = ("basis_functions", "occupied_cells", "memory_bytes")

Where = Literal["thesis_point", "rule", "equal_size", "equal_fidelity"]
Relation = Literal["better", "similar", "undecided"]


@dataclass(frozen=True)
class Compare:
    """``better`` beats ``other`` on ``metric`` (see the module docstring for ``at``).

    ``factor``: the claimed ratio other/better for ratio metrics (sizes, time), e.g. 20
    for "twenty times fewer". ``relation="similar"``: the ratio lies within
    ``1 +/- tolerance`` ("almost the same"); ``"undecided"``: neither is better (the
    interval of the difference contains zero). ``size``/``fidelity``: the x column of
    equal-size reads and the y column of equal-fidelity reads; ``levels`` fixes the
    sizes or fidelities read at (empty: three levels inside the fronts' overlap).
    """

    case: str
    better: str
    other: str
    metric: str
    at: Where
    higher_is_better: bool = False
    relation: Relation = "better"
    factor: float = 1.0
    tolerance: float = 0.25
    size: str = "basis_functions"
    fidelity: str = "mhd_m"
    levels: tuple[float, ...] = ()


@dataclass(frozen=True)
class Trend:
    """``metric`` rises (``sign=+1``) or falls (-1) with ``x`` (a parameter or a column).

    Per terrain and seed: Spearman's rho between the levels of ``x`` and the mean of
    ``metric`` at each level; the claim needs ``sign * rho > min_rho``.
    ``largest_half`` keeps only the larger half of the mapper's maps (by ``size``).
    """

    case: str
    mapper: str
    x: str
    metric: str
    sign: int
    min_rho: float = 0.5
    largest_half: bool = False
    size: str = "basis_functions"


@dataclass(frozen=True)
class Optimum:
    """``metric`` (lower is better) is best at an interior level of parameter ``x``: the
    finest setting (``finest="low"``: smallest value of ``x``) is worse than the best
    interior one. Statistic: metric at the finest level minus the interior minimum."""

    case: str
    mapper: str
    x: str
    metric: str
    finest: Literal["low", "high"]


@dataclass(frozen=True)
class Effect:
    """Parameter ``param`` moves ``metric`` more than parameter ``other`` does, or (with
    ``max_spread``) less than that relative spread. The spread of a parameter is the
    range of the metric over its levels among settings equal in every other parameter,
    averaged over those settings, relative to the metric's mean."""

    case: str
    mapper: str
    metric: str
    param: str
    other: str | None = None
    max_spread: float | None = None


@dataclass(frozen=True)
class Agreement:
    """``metric`` agrees with the ground-truth ``reference`` over a mapper's settings.

    Agreement = ``sign`` * Spearman rho(metric, reference) (``sign=-1`` when the
    reference is higher-is-better, e.g. completeness). With ``other``: ``metric``
    agrees better than ``other`` does; without: the claim is that ``metric`` does NOT
    agree beyond ``min_rho`` ("not sensitive enough").
    """

    case: str
    mapper: str
    metric: str
    reference: str
    sign: int = 1
    other: str | None = None
    min_rho: float = 0.5


@dataclass(frozen=True)
class Summary:
    """An aggregate of ``column`` over each mapper's settings (``agg``: ``"median"`` or
    ``"cv"``, the coefficient of variation std/mean): ``better`` beats ``other``, or,
    with ``other=None``, ``better``'s aggregate beats ``threshold``."""

    case: str
    better: str
    column: str
    agg: Literal["median", "cv"]
    other: str | None = None
    higher_is_better: bool = False
    threshold: float = 0.0


@dataclass(frozen=True)
class Contrast:
    """An aggregate of ``column`` over ``mapper``'s settings (as in :class:`Summary`) is
    better in the base grid than in ablation ``variant`` (the grid with one thing
    changed), read per terrain and seed on the variant's terrains of the case; the base
    is better when lower (``higher_is_better``: when higher)."""

    case: str
    mapper: str
    column: str
    agg: Literal["median", "cv"]
    variant: str
    higher_is_better: bool = False


@dataclass(frozen=True)
class Property:
    """Boolean class attribute ``attribute`` of the mapper implementations (e.g.
    ``incremental``): true for every mapper in ``true`` and false for those in ``false``."""

    attribute: str
    true: tuple[str, ...]
    false: tuple[str, ...] = ()


@dataclass(frozen=True)
class NotMeasurable:
    """No measurement in our data decides the claim; ``reason`` says why."""

    reason: str


Check = (Compare | Trend | Optimum | Effect | Agreement | Summary | Contrast | Property
         | NotMeasurable)


def renamed(check: Check, column: str, to: str) -> Check:
    """``check`` with every field naming ``column`` naming ``to`` instead."""
    changes = {f.name: to for f in fields(check) if getattr(check, f.name) == column}
    # Only fields that held a column name (text) change; mypy checks the keywords of
    # ``replace`` against every field of every kind of check at once.
    return replace(check, **changes)  # type: ignore[arg-type]


@dataclass(frozen=True)
class AllOf:
    """A conjunction: the quote makes every one of ``parts``' comparisons."""

    parts: tuple[Check, ...]


@dataclass(frozen=True)
class Claim:
    """A comparative claim: verbatim ``quote``, thesis ``section``, its ``check`` and
    ``reading`` (how the words were turned into the check, where that needed a choice).

    Claims from tables 5.1-5.4 quote the two compared cells as "Criterion: Mapper
    Label, Mapper Label"; every other quote is the thesis' text, verbatim.
    """

    id: str
    section: str
    quote: str
    check: Check | AllOf
    reading: str = ""
