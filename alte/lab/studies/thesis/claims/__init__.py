"""The thesis' comparative claims (chapters 5 and 6) as typed, checkable data.

:data:`CLAIMS` lists every comparative claim, quoted verbatim with its section; each
carries a check (:mod:`alte.lab.studies.thesis.claims.types`) that
:mod:`alte.lab.studies.analysis.evidence`
evaluates on a trade-off table.
"""

from alte.lab.studies.thesis.claims.ch5 import CH5_CLAIMS
from alte.lab.studies.thesis.claims.ch6 import CH6_CLAIMS
from alte.lab.studies.thesis.claims.types import (
    CASES,
    SIZE_COLUMNS,
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
    Relation,
    Summary,
    Trend,
    Where,
)

__all__ = ["CASES", "CLAIMS", "SIZE_COLUMNS", "Agreement", "AllOf", "Check", "Claim", "Compare",
           "Contrast", "Effect", "NotMeasurable", "Optimum", "Property", "Relation", "Summary",
           "Trend",
           "Where", "claim"]

#: Every comparative claim of thesis chapters 5 and 6, in the thesis' order.
CLAIMS: tuple[Claim, ...] = CH5_CLAIMS + CH6_CLAIMS


def claim(claim_id: str) -> Claim:
    """The claim with id ``claim_id``."""
    from alte.errors import ParameterError

    for item in CLAIMS:
        if item.id == claim_id:
            return item
    raise ParameterError(f"no claim {claim_id!r}; ids: {', '.join(c.id for c in CLAIMS)}")
