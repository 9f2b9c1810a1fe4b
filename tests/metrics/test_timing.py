"""A map's time as a measured quantity: medians and spreads of repeated readings."""

import math

import numpy as np
import pytest

from alte.errors import MetricsError
from alte.metrics.timing import Timing, log_spread


def test_the_spread_is_half_the_log_of_max_over_min():
    assert log_spread([1.0, 2.0, 4.0]) == pytest.approx(math.log(4.0) / 2)
    assert log_spread([3.0, 3.0]) == 0.0
    assert math.isnan(log_spread([1.0])) and math.isnan(log_spread([0.0, 1.0]))


def test_timing_of_paired_readings_takes_medians():
    timing = Timing.of([0.03, 0.01, 0.02], [0.012, 0.010, 0.011])
    assert (timing.elapsed_s, timing.cpu_s, timing.repeats) == (0.02, 0.011, 3)
    assert timing.elapsed_spread == pytest.approx(math.log(3) / 2)
    assert timing.cpu_spread == pytest.approx(math.log(1.2) / 2)
    once = Timing.of([0.5], [0.4])
    assert once.repeats == 1 and np.isnan(once.cpu_spread) and np.isnan(once.elapsed_spread)
    with pytest.raises(MetricsError, match="2 wall and 1 CPU readings"):
        Timing.of([0.1, 0.2], [0.1])
    with pytest.raises(MetricsError, match="at least one"):
        Timing.of([], [])
