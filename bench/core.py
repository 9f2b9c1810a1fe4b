"""What every benchmark row shares: the run's settings, a per-process cache, and results.

A row is a function ``Context -> list[Result]``; a :class:`Result` holds both
absolute figures, their ratio (ours / peer) and whether its target is met.
The :class:`Context` loads each terrain once and memoises expensive shared work
(e.g. the Octomap passes rows 1, 2, 4 and 5 read).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TypeVar, cast

import numpy as np

from alte.params import Record, param
from alte.types import JSONDict
from bench.workload import Scan, Workload, load_workload

__all__ = ["LIMITS", "BenchSettings", "Context", "Result"]

T = TypeVar("T")
FULL_SIZES = (10**4, 10**5, 10**6, 10**7)
QUICK_SIZES = (3000, 6000, 12000)
DATA_DIR, REPORTS_DIR = Path("data"), Path("reports")
#: Largest ratio ours / peer meeting each row's target (rows 7 and 8 have none; row 9
#: also has a ceiling in MB; row 15 one in CPU seconds a tile).
LIMITS: dict[int, float] = {1: 1 / 3, 2: 1.0, 3: 10.0, 4: 0.5, 5: 0.1, 6: 2.0, 9: 1.15, 10: 0.1,
                            11: 1.0, 12: 1.2, 15: 1.2}


@dataclass(frozen=True)
class BenchSettings(Record):
    """Settings of one benchmark run (validated like every parameter record)."""

    OWNER = "bench"

    quick: bool = param(False, help="small terrains and sizes")
    repeats: int = param(5, lambda v: v >= 1, "repeats >= 1", "timed repeats")
    warmup: int = param(1, lambda v: v >= 0, "warmup >= 0", "discarded warm-up runs")
    frames: int | None = param(None, lambda v: v >= 1, "frames >= 1, or None for all",
                               "scans of rows 1, 2 and 4 (and 9 in quick mode)")
    sizes: tuple[int, ...] = param((), lambda v: all(n >= 2 for n in v),
                                   "every size >= 2", "row 7's point counts")
    budget_s: float = param(60.0, lambda v: v > 0, "budget_s > 0",
                            "skip a row-7 size whose predicted single run is longer (s)")
    data_dir: Path = param(DATA_DIR, help="where the bench terrains live")
    reports_dir: Path = param(REPORTS_DIR, help="where bench.md/json are written")
    progress: bool = param(True, help="progress bars")

    @property
    def scaling_sizes(self) -> tuple[int, ...]:
        """Row 7's sizes: the given ones, else the mode's default."""
        return self.sizes or (QUICK_SIZES if self.quick else FULL_SIZES)


@dataclass
class Result:
    """One line of the table: ``ours`` and ``peer`` in ``unit``, the target and its verdict."""

    row: int
    case: str
    ours: float
    peer: float
    unit: str
    target: str
    met: bool | None
    detail: JSONDict = field(default_factory=dict)

    @property
    def ratio(self) -> float:
        """ours / peer (NaN when the peer is 0)."""
        return self.ours / self.peer if self.peer else float("nan")

    def as_dict(self) -> JSONDict:
        """JSON-ready row."""
        return {"row": self.row, "case": self.case, "ours": self.ours, "peer": self.peer,
                "unit": self.unit, "ratio": self.ratio, "target": self.target,
                "met": self.met, "detail": self.detail}


class Context:
    """The run's config plus a cache of loaded terrains and shared measurements."""

    def __init__(self, config: BenchSettings) -> None:
        self.config = config
        self._memo: dict[str, object] = {}

    def memo(self, key: str, make: Callable[[], T]) -> T:
        """``make()`` once per process and key (a key always names the same kind of value,
        so the cached one is what ``make`` returns)."""
        if key not in self._memo:
            self._memo[key] = make()
        return cast("T", self._memo[key])

    def has(self, key: str) -> bool:
        """True when ``key`` is already memoised."""
        return key in self._memo

    def workload(self, terrain: str) -> Workload:
        """The terrain's registered frames and merged cloud (loaded once)."""
        cfg = self.config
        return self.memo(f"workload:{terrain}", lambda: load_workload(
            terrain, cfg.data_dir, quick=cfg.quick, progress=cfg.progress))

    def scans(self, terrain: str) -> list[Scan]:
        """The frames rows 1, 2 and 4 insert: all, or ``config.frames`` evenly spaced."""
        frames = self.workload(terrain).frames
        limit = self.config.frames
        if limit is None or limit >= len(frames):
            return frames
        pick = np.unique(np.round(np.linspace(0, len(frames) - 1, limit)).astype(int))
        return [frames[i] for i in pick]
