"""The time a mapper needs for a fidelity: the least time of its maps reaching it."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from alte.lab.studies.analysis.time_needed import READ_COLUMNS, time_at_fidelity
from alte.lab.studies.analysis.uncertainty import RUN_TIME_SPREAD


def _maps(mapper: str, times, mhds, spreads=None) -> pd.DataFrame:
    n = len(times)
    return pd.DataFrame({"terrain": "t", "seed": 0, "mapper": mapper, "map_cpu_s": times,
                         "mhd_m": mhds, "basis_functions": np.arange(1, n + 1) * 100,
                         "map_cpu_spread": spreads if spreads is not None else [0.0] * n})


def test_the_least_time_of_the_maps_reaching_each_level():
    # the fastest map is not the coarsest: no front, no censoring, just the least time
    table = pd.concat([_maps("a", [3.0, 1.0, 2.0], [0.5, 0.9, 0.3]),
                       _maps("b", [1.0, 1.0, 1.0], [0.4, 0.4, 0.4])])
    reads = time_at_fidelity(table, ("a", "b"), "map_cpu_s", levels=(0.2, 0.35, 0.6, 1.0))
    assert list(reads.columns) == READ_COLUMNS
    a = reads[reads["mapper"] == "a"].set_index("level")
    assert np.isnan(a.loc[0.2, "value"])  # no map reaches it
    assert a.loc[0.35, "value"] == 2.0 and a.loc[0.6, "value"] == 2.0
    assert a.loc[1.0, "value"] == 1.0
    # bounds: the least of the lower and of the upper times, each within the run spread
    assert a.loc[1.0, "low"] == pytest.approx(np.exp(-RUN_TIME_SPREAD))
    assert a.loc[1.0, "high"] == pytest.approx(np.exp(RUN_TIME_SPREAD))


def test_a_maps_own_repeat_spread_does_not_widen_its_bounds():
    # the repeats' spread says how loaded the machine was in that second; two mappers'
    # times are compared within one run-to-run spread, so a noisy map widens nothing
    table = pd.concat([_maps("a", [1.0, 2.0], [0.9, 0.3], spreads=[0.7, 0.0]),
                       _maps("b", [1.0], [0.3])])
    reads = time_at_fidelity(table, ("a", "b"), "map_cpu_s", levels=(0.3, 1.0))
    a = reads[reads["mapper"] == "a"].set_index("level")
    assert a.loc[0.3, "high"] == pytest.approx(2.0 * np.exp(RUN_TIME_SPREAD))
    assert a.loc[1.0, "low"] == pytest.approx(np.exp(-RUN_TIME_SPREAD))
    assert a.loc[1.0, "high"] == pytest.approx(np.exp(RUN_TIME_SPREAD))


def test_levels_come_from_the_size_fronts_and_terrains_need_both_mappers():
    table = pd.concat([_maps("a", [3.0, 1.0, 2.0], [0.5, 0.9, 0.3]),
                       _maps("b", [1.0, 2.0, 4.0], [0.8, 0.5, 0.2]),
                       _maps("a", [1.0], [0.5]).assign(terrain="only_a")])
    reads = time_at_fidelity(table, ("a", "b"), "map_cpu_s")
    assert set(reads["terrain"]) == {"t"} and reads["level"].nunique() == 3
    # the levels do not depend on the times: scaling one mapper's times keeps them
    slower = table.assign(map_cpu_s=np.where(table["mapper"] == "a", 10.0, 1.0)
                          * table["map_cpu_s"])
    again = time_at_fidelity(slower, ("a", "b"), "map_cpu_s")
    assert list(again["level"]) == list(reads["level"])
