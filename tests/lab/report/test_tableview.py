"""Tables for readers: units in headers, ours beside the thesis', key columns."""

from __future__ import annotations

import numpy as np
import pandas as pd

from alte.lab.report.tableview import cell_text, header, table_view


def test_headers_carry_units():
    assert header("mhd_m") == "MHD [m]" and header("elapsed_s") == "mapping time [s]"
    assert header("cell_min_m") == "cell min [m]" and header("wall_s") == "wall [s]"
    assert header("frames") == "frames" and header("thesis_params") == "thesis' parameters"


def test_cells_are_formatted_for_reading():
    assert cell_text(np.nan) == "\u2013" and cell_text(None) == "\u2013"
    assert cell_text(1234567) == "1,234,567" and cell_text(4399.0) == "4,399"
    assert cell_text(0.123456) == "0.1235" and cell_text(3.0) == "3"
    assert cell_text("alte2d", "mapper") == "2D-ALTE" and cell_text(True) == "yes"


def test_thesis_twins_become_paired_columns():
    frame = pd.DataFrame({"mapper": ["quadtree"], "max_points": [150], "mhd_m": [0.6],
                          "thesis_mhd_m": [1.09], "memory_bytes": [10], "thesis_row": [2]})
    view = table_view(frame, key=True)
    assert view.top == [("mapper", 1), ("max_points".replace("_", " "), 1), ("MHD [m]", 2)]
    assert view.sub == ["ours", "thesis"]
    assert view.rows == [["Quadtree", "150", "0.6", "1.09"]]
    full = table_view(frame)
    assert ("memory [B]", 1) in full.top and ("thesis row", 1) in full.top
    assert full.shape == (1, 6)


def test_a_params_column_replaces_the_parameter_columns_and_rows_can_be_capped():
    frame = pd.DataFrame({"mapper": ["a", "b", "c"], "params": ["k=1", "k=2", "k=3"],
                          "kappa": [1, 2, 3], "mean": [0.1, 0.2, 0.3]})
    view = table_view(frame, key=True, max_rows=2)
    assert [t for t, _ in view.top] == ["mapper", "parameters", "mean"]
    assert len(view.rows) == 2 and view.shape == (3, 4)
