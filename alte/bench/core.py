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
from typing import Any, TypeVar

import numpy as np

from alte.bench.timing import check_counts
from alte.bench.workload import Workload, load_workload
from alte.errors import ParameterError

__all__ = ["LIMITS", "BenchConfig", "Context", "Result"]

T = TypeVar("T")
FULL_SIZES = (10**4, 10**5, 10**6, 10**7)
QUICK_SIZES = (3000, 6000, 12000)
#: Largest ratio ours / peer meeting each row's target (rows 7 and 8 have none; row 9
#: also has a ceiling in MB).
LIMITS: dict[int, float] = {1: 1 / 3, 2: 1.0, 3: 10.0, 4: 1.0, 5: 1.0, 6: 2.0, 9: 1.15}


@dataclass(frozen=True)
class BenchConfig:
    """Settings of one benchmark run.

    ``frames`` limits the scans of rows 1, 2 and 4, and of row 9 in quick mode (None =
    every frame; row 5 always
    inserts every frame);
    ``sizes`` are row 7's point counts (default 10^4..10^7, quick 3000..12000);
    ``budget_s`` skips a row-7 size whose predicted single run exceeds it.
    """

    quick: bool = False
    repeats: int = 5
    warmup: int = 1
    frames: int | None = None
    sizes: tuple[int, ...] = ()
    budget_s: float = 60.0
    data_dir: Path = Path("data")
    reports_dir: Path = Path("reports")
    progress: bool = True

    def __post_init__(self) -> None:
        check_counts(self.repeats, self.warmup)
        if self.frames is not None and self.frames < 1:
            raise ParameterError(f"bench: frames={self.frames} must be >= 1 (or None = all)")
        if any(n < 2 for n in self.sizes):
            raise ParameterError(f"bench: sizes {list(self.sizes)} must all be >= 2")
        if not self.budget_s > 0:
            raise ParameterError(f"bench: budget_s={self.budget_s} must be > 0")

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
    detail: dict[str, Any] = field(default_factory=dict)

    @property
    def ratio(self) -> float:
        """ours / peer (NaN when the peer is 0)."""
        return self.ours / self.peer if self.peer else float("nan")

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready row."""
        return {"row": self.row, "case": self.case, "ours": self.ours, "peer": self.peer,
                "unit": self.unit, "ratio": self.ratio, "target": self.target,
                "met": self.met, "detail": self.detail}


class Context:
    """The run's config plus a cache of loaded terrains and shared measurements."""

    def __init__(self, config: BenchConfig) -> None:
        self.config = config
        self._memo: dict[str, Any] = {}

    def memo(self, key: str, make: Callable[[], T]) -> T:
        """``make()`` once per process and key."""
        if key not in self._memo:
            self._memo[key] = make()
        return self._memo[key]

    def has(self, key: str) -> bool:
        """True when ``key`` is already memoised."""
        return key in self._memo

    def workload(self, terrain: str) -> Workload:
        """The terrain's registered frames and merged cloud (loaded once)."""
        cfg = self.config
        return self.memo(f"workload:{terrain}", lambda: load_workload(
            terrain, cfg.data_dir, quick=cfg.quick, progress=cfg.progress))

    def scans(self, terrain: str) -> list[tuple[np.ndarray, np.ndarray]]:
        """The frames rows 1, 2 and 4 insert: all, or ``config.frames`` evenly spaced."""
        frames = self.workload(terrain).frames
        limit = self.config.frames
        if limit is None or limit >= len(frames):
            return frames
        pick = np.unique(np.round(np.linspace(0, len(frames) - 1, limit)).astype(int))
        return [frames[i] for i in pick]
