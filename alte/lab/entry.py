"""What a study declares to the report: its notebook runs and the tables it puts in front.

Each study folder holds a ``report`` module with its :class:`Entry` objects (the notebook,
its parameters in quick and full mode, the chapter's title) and, where it has them, its
:class:`KeyTable` objects; :mod:`alte.lab.report.plan` and :mod:`alte.lab.report.captions`
only collect them. The types live here, below both, so a study never imports the report.
"""


from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar

from alte.params import Record, param
from alte.types import JSON, JSONMap  # noqa: F401  (Record resolves JSONMap's "JSON" here)

__all__ = ["QUICK_FRAMES", "Entry", "KeyTable"]

#: Scans per terrain in quick mode, the same in every notebook: the simulated terrain
#: (cached per frame count by ``ensure_terrain``) is then made once and shared.
QUICK_FRAMES = 40


@dataclass(frozen=True)
class Entry(Record):
    """One planned notebook run; ``quick``/``full`` are its parameters (None = skipped)."""

    OWNER: ClassVar[str] = "plan entry"
    name: str = param("", bool, "a non-empty name", "the run's name")
    notebook: str = param("", lambda v: v.endswith(".ipynb"), "an .ipynb file name",
                          "the notebook it runs")
    quick: JSONMap | None = field(default_factory=dict)
    full: JSONMap | None = field(default_factory=dict)
    terrains: tuple[str, ...] = param((), help="the terrains it needs besides TERRAIN")
    first: bool = param(False, help="started before the others when notebooks run in "
                                     "parallel (the longest, so the rest fill the other core)")
    title: str = param("", help="its section's title on the front page ({NAME} fields are "
                                "filled from the run's parameters); empty: the run's name")


@dataclass(frozen=True)
class KeyTable:
    """A CSV shown on the front page with the thesis' values beside ours.

    ``rank`` orders the key tables of every study on the page (lowest first).
    """

    name: str
    title: str
    text: str
    key: bool = True
    hide: tuple[str, ...] = ()
    rows: int = 60
    rank: int = 0
