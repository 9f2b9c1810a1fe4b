"""What a check reads: the rows of a case and its mappers, display names and units."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from alte.lab.studies.analysis.checks import NoDataError, case_rows, name, unit


def _table(with_case: bool) -> pd.DataFrame:
    table = pd.DataFrame({
        "terrain": ["sim_lan_1", "sim_lan_2", "sim_nav_1", "sim_lan_1", "sim_lan_1"],
        "mapper": ["alte2d", "alte2d", "alte2d", "quadtree", "octomap"],
        "mhd_m": [0.1, 0.2, 0.3, 0.4, 0.5],
        "hd_m": [1.0, np.nan, 3.0, np.nan, 5.0],
        "empty": [np.nan] * 5})
    # a case column overrides the terrain's case (a real recording names its own)
    return table.assign(case=["lan", "nav", "lan", "lan", "lan"]) \
        if with_case else table


def test_rows_of_a_case_and_its_mappers() -> None:
    by_terrain = case_rows(_table(False), "lan", ["alte2d", "quadtree"], ["mhd_m"])
    assert by_terrain["mhd_m"].tolist() == [0.1, 0.2, 0.4]
    by_column = case_rows(_table(True), "lan", ["alte2d", "quadtree"], ["mhd_m"])
    assert by_column["mhd_m"].tolist() == [0.1, 0.3, 0.4]
    # a column with one value among the rows is enough
    assert len(case_rows(_table(False), "lan", ["alte2d", "quadtree"], ["hd_m"])) == 3


def test_what_is_missing_is_named() -> None:
    with pytest.raises(NoDataError, match=r"^no rows of quadtree, octomap on the nav "
                                          r"terrains$"):
        case_rows(_table(False), "nav", ["alte2d", "quadtree", "octomap"], ["mhd_m"])
    with pytest.raises(NoDataError, match=r"^no values in column\(s\) empty, absent$"):
        case_rows(_table(False), "lan", ["alte2d"], ["mhd_m", "empty", "absent"])
    with pytest.raises(NoDataError, match=r"column\(s\) hd_m$"):
        case_rows(_table(False), "lan", ["quadtree"], ["hd_m"])   # NaN in every row


def test_display_names_and_units() -> None:
    assert [name(m) for m in ("alte2d", "alte3d", "quadtree", "octomap", "dufomap")] == [
        "2D-ALTE", "3D-ALTE", "Quadtree", "Octomap", "dufomap"]
    assert [unit(m) for m in ("mhd_m", "memory_bytes", "elapsed_s", "completeness",
                              "unheard_of")] == ["m", "B", "s", "", ""]
