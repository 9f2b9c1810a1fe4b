"""numpy <-> open3d tensor conversions: dtype, layout, independent copies."""

from __future__ import annotations

import numpy as np
import open3d as o3d

from alte.tensors import to_array, to_tensor


def test_to_tensor_copies_in_the_requested_dtype_and_c_order() -> None:
    values = np.arange(12, dtype=np.float64).reshape(3, 4).T  # (4, 3), not C-contiguous
    tensor = to_tensor(values)
    assert tensor.dtype == o3d.core.float32
    assert tuple(tensor.shape) == (4, 3)
    assert tensor.is_contiguous()
    np.testing.assert_array_equal(tensor.numpy(), values.astype(np.float32))
    values[0, 0] = 99.0  # the tensor holds its own copy
    assert tensor.numpy()[0, 0] == 0.0


def test_to_tensor_indices_are_uint32() -> None:
    tensor = to_tensor(np.array([[0, 1, 2]], dtype=np.int64), np.uint32)
    assert tensor.dtype == o3d.core.uint32
    np.testing.assert_array_equal(tensor.numpy(), [[0, 1, 2]])


def test_to_array_round_trip_is_an_independent_copy() -> None:
    tensor = to_tensor([[1.5, -2.0, 3.25]])
    out = to_array(tensor, np.float64)
    assert out.dtype == np.float64
    np.testing.assert_array_equal(out, [[1.5, -2.0, 3.25]])
    out[0, 0] = 0.0
    assert tensor.numpy()[0, 0] == 1.5
