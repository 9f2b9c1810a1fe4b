"""What the ground-truth metrics are given: their settings and the true scene.

Apart from :mod:`~alte.metrics.maps` so that :mod:`~alte.metrics.reference` reads them
without importing the module that uses it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from alte.params import Record, param

if TYPE_CHECKING:
    from alte.metrics.surface import TrueSurface
    from alte.types import Box

__all__ = ["GroundTruth", "TruthSettings"]


@dataclass(frozen=True)
class TruthSettings(Record):
    """Ground-truth metric settings (see :mod:`alte.metrics.truth`), a parameter record."""

    OWNER = "truth"

    tolerance: float = param(0.2, lambda v: v > 0, "tolerance > 0",
                             "how close a map must come to a true surface to map it (m)")
    n_samples: int = param(100_000, lambda v: v >= 1, "n_samples >= 1",
                           "surface samples drawn (3D)")
    grid_step: float = param(0.2, lambda v: v > 0, "grid_step > 0",
                             "x/y probe spacing of the 2D metrics (m)")
    seed: int = param(0, lambda v: v >= 0, "seed >= 0", "sampling seed")


@dataclass(frozen=True, eq=False)
class GroundTruth:
    """The true surface of a simulated terrain and its control volume."""

    surface: TrueSurface
    bounds: Box
