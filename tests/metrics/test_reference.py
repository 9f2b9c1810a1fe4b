"""alte.metrics.reference: the cloud and truth prepared once give measure_map's values; a
reference made from other inputs is refused; per-leaf values are computed once."""

from __future__ import annotations

import numpy as np
import pytest

from alte.errors import MetricsError
from alte.mappers import make_mapper
from alte.metrics.leaves import PerLeaf
from alte.metrics.maps import SET_B, measure_map
from alte.metrics.reference import Reference


def _cloud(seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    xy = rng.uniform(0, 30, (20_000, 2))
    z = np.where((xy[:, 0] > 10) & (xy[:, 0] < 14), 3.0, 0.0) + rng.normal(0, 0.02, len(xy))
    return np.column_stack([xy, z])


def test_hausdorff_through_a_reference_equals_the_plain_call():
    cloud = _cloud()
    reference = Reference(cloud)
    for mapper, params in (("quadtree", {"max_points": 80}), ("alte3d", {"max_res": 6})):
        m = make_mapper(mapper, params)
        m.build(cloud)
        for set_b in SET_B:
            plain = measure_map(m, cloud, elapsed_s=0.0, set_b=set_b)
            fast = measure_map(m, cloud, elapsed_s=0.0, set_b=set_b, reference=reference)
            assert plain == fast, (mapper, set_b)
    assert reference.fresh().cloud_index is reference.cloud_index  # prepared once


def test_a_reference_of_other_inputs_is_refused():
    cloud = _cloud()
    m = make_mapper("quadtree", {})
    m.build(cloud)
    with pytest.raises(MetricsError, match="reference was prepared from another cloud"):
        measure_map(m, cloud, elapsed_s=0.0, reference=Reference(_cloud(1)))
    assert measure_map(m, cloud.copy(), elapsed_s=0.0, reference=Reference(cloud)).hd_m > 0


def test_per_leaf_values_are_computed_once_in_any_order():
    calls = []

    def square(rows: np.ndarray) -> np.ndarray:
        calls.append(rows.tolist())
        return rows.astype(np.float64) ** 2

    cache = PerLeaf(np.float64)
    assert cache.get(np.array([5, 2, 5]), square).tolist() == [25.0, 4.0, 25.0]
    assert cache.get(np.array([2, 9, 0, 9]), square).tolist() == [4.0, 81.0, 0.0, 81.0]
    assert cache.get(np.array([0, 5]), square).tolist() == [0.0, 25.0]
    assert calls == [[2, 5], [0, 9]]
    assert cache.get(np.array([], np.int64), square).size == 0
