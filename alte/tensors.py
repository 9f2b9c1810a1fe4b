"""numpy arrays to open3d tensors and back, with types.

open3d's stubs make ``Tensor``'s dtype and device arguments required and type
``Tensor.numpy()`` as ``Any``; these two functions give the ray-casting callers
(metrics, sim, studies) typed arrays at that boundary. open3d is imported on first
use, as everywhere else, so importing this module stays cheap.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, TypeVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

if TYPE_CHECKING:
    import open3d as o3d

__all__ = ["to_array", "to_tensor"]

_T = TypeVar("_T", np.float32, np.float64, np.int64)


def to_tensor(values: ArrayLike, dtype: type[np.float32 | np.uint32] = np.float32,
              ) -> o3d.core.Tensor:
    """A C-contiguous copy of ``values`` as an open3d CPU tensor of ``dtype``."""
    import open3d as o3d

    return o3d.core.Tensor.from_numpy(np.array(values, dtype=dtype, order="C"))


def to_array(tensor: o3d.core.Tensor, dtype: type[_T]) -> NDArray[_T]:
    """A copy of ``tensor`` as a numpy array of ``dtype``."""
    return np.array(tensor.numpy(), dtype=dtype)
