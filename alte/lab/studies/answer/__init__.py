"""The bottom line of the report: which map to build, for which use, under which budget.

:mod:`~alte.lab.studies.answer.choose` picks a mapper and setting per use, terrain group and
budget from the trade-off grid; :mod:`~alte.lab.studies.answer.orders` reads which mapper
leads at equal size by a metric (the thesis' MHD, the truth, a real sequence);
:mod:`~alte.lab.studies.answer.assemble` assembles the front page's answer from the tables.
"""

from alte.lab.studies.answer.assemble import (
    BottomLine,
    RealCheck,
    UseAnswer,
    bottom_line,
    interval_text,
    pick_text,
)
from alte.lab.studies.answer.choose import (
    GROUPS,
    MIN_COMPLETENESS,
    SIZE_BUDGETS,
    USES,
    Budget,
    Choice,
    Pick,
    Use,
    budgets,
    candidates,
    choose,
    ms_per_scan,
)
from alte.lab.studies.answer.orders import HIGHER, Order, agreement, order

__all__ = ["GROUPS", "HIGHER", "MIN_COMPLETENESS", "SIZE_BUDGETS", "USES", "BottomLine", "Budget",
           "Choice", "Order", "Pick", "RealCheck", "Use", "UseAnswer", "agreement", "bottom_line",
           "budgets", "candidates", "choose", "interval_text", "ms_per_scan", "order",
           "pick_text"]
