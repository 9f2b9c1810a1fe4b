"""Array types of the plotting functions' arguments, and one matplotlib adapter."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TypeAlias, cast

import numpy as np
from numpy.typing import NDArray

__all__ = ["Bools", "Floats", "Ints", "polygons"]

#: Coordinates, heights and other reals.
Floats: TypeAlias = NDArray[np.float64]
#: Masks.
Bools: TypeAlias = NDArray[np.bool_]
#: Indices, labels and counts.
Ints: TypeAlias = NDArray[np.int64]


def polygons(verts: Floats) -> Sequence[Floats]:
    """(K, V, 2) polygon corners as ``PolyCollection`` takes them: the array itself, which
    matplotlib handles in one piece (its stubs ask for a sequence of polygons)."""
    return cast("Sequence[Floats]", verts)
