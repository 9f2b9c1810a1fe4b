"""The plugin authors' example mapper (docs/examples/mean_grid.py) for the tests, and a
variant whose cells carry a height variance."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path
from types import ModuleType
from typing import ClassVar

import numpy as np

from alte.mappers.api import VARIANCE, Cells

__all__ = ["EXAMPLE", "MeanGrid", "NoisyGrid", "example_module"]

#: The example file of docs/how-to/write-a-mapper.md.
EXAMPLE = Path(__file__).parents[2] / "docs" / "examples" / "mean_grid.py"


def example_module() -> ModuleType:
    """docs/examples/mean_grid.py imported (as ``mean_grid``, once)."""
    if "mean_grid" in sys.modules:
        return sys.modules["mean_grid"]
    spec = importlib.util.spec_from_file_location("mean_grid", EXAMPLE)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules["mean_grid"] = module
    spec.loader.exec_module(module)
    return module


MeanGrid = example_module().MeanGrid


class NoisyGrid(MeanGrid):  # type: ignore[misc, valid-type]
    """The example with a height variance: (5 cm)^2 over the cell's point count."""

    name = "noisygrid"
    title = "Noisy grid"
    layers: ClassVar[frozenset[str]] = frozenset({VARIANCE})

    def cells(self) -> Cells:
        cells = super().cells()
        count = np.asarray(self._count, dtype=np.float64)
        return Cells(cells.centers, cells.sizes, cells.value, cells.occupied, cells.level,
                     {VARIANCE: 0.05**2 / count})
