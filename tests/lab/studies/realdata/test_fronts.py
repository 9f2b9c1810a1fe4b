"""The fronts on a real sequence: distances to a reference cloud, the table, the figure."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from alte.lab.studies import realdata
from alte.lab.studies.realdata import figures as realdata_plot
from alte.mappers.base import Cells
from alte.paths import realdata_dir


def _cells(centers: np.ndarray, edge: float, dims: int) -> Cells:
    sizes = np.full(centers.shape, edge)
    if dims == 2:
        sizes[:, 2] = 0.0
    n = len(centers)
    return Cells(centers, sizes, np.ones(n), np.ones(n, bool), np.zeros(n, int))


def test_a_2d_map_is_read_against_the_highest_reference_point_per_pixel():
    xy = np.stack(np.meshgrid(np.arange(0.25, 10, 0.5), np.arange(0.25, 10, 0.5)),
                  -1).reshape(-1, 2)
    ground = np.column_stack([xy, np.full(len(xy), 1.1)])
    low = ground - [0.0, 0.0, 1.0]  # under the top: never the reference height
    reference = np.vstack([ground, low])
    centers = np.array([[x + 1.0, y + 1.0, 1.0] for x in (0.0, 2.0, 4.0, 6.0, 8.0)
                        for y in (0.0, 2.0, 4.0, 6.0, 8.0)])
    out = realdata.reference_metrics(_cells(centers, 2.0, 2), 2, reference, step=0.5)
    assert out["height_rmse_m"] == pytest.approx(0.1)
    assert out["completeness"] == 1.0
    # every centre lies between four reference points, 0.25 m off in x and y, 0.1 m below
    assert out["accuracy_mean_m"] == pytest.approx(np.sqrt(0.25**2 + 0.25**2 + 0.1**2))
    strict = realdata.reference_metrics(_cells(centers, 2.0, 2), 2, reference, tolerance=0.05)
    assert strict["completeness"] == 0.0


def test_a_3d_map_covers_the_reference_points_within_its_boxes():
    reference = np.array([[0.5, 0.5, 0.5], [0.5, 0.5, 1.1], [5.0, 5.0, 5.0]])
    cells = _cells(np.array([[0.5, 0.5, 0.5]]), 1.0, 3)
    out = realdata.reference_metrics(cells, 3, reference, tolerance=0.2)
    assert out["completeness"] == pytest.approx(2 / 3)  # 1.1 is 0.1 m above the box
    assert out["accuracy_mean_m"] == 0.0 and np.isnan(out["height_rmse_m"])


def test_without_the_sequence_the_table_is_empty_with_its_columns(tmp_path: Path):
    data = realdata.locate(tmp_path / "nowhere")
    assert realdata.sequence_data(data) is None
    table = realdata.front_table(None)
    assert table.empty and list(table.columns) == list(realdata.FRONT_COLUMNS)
    assert realdata_plot.fronts_figure(table) is None


@pytest.mark.realdata
def test_the_real_sequence_gives_fronts_in_the_trade_off_schema(tmp_path: Path):
    data = realdata.locate(realdata_dir())
    if not data.available:
        pytest.skip("../shared/realdata absent")
    sequence = realdata.sequence_data(data, frames=3, voxel=1.0, cache=tmp_path)
    assert len(sequence.data) == 3 and len(sequence.reference) > len(sequence.data.cloud)
    grid = {"quadtree": [{"max_points": 200}], "alte2d": [{"kappa": 0.1, "max_res": 5}],
            "octomap": [{"resolution": 0.5}], "alte3d": [{"max_res": 5, "min_pts": 1}]}
    table = realdata.front_table(sequence, grid, progress=False)
    assert table["mapper"].tolist() == ["quadtree", "alte2d", "octomap", "alte3d"]
    assert table["case"].tolist() == ["lan", "lan", "nav", "nav"]
    assert (table["basis_functions"] > 0).all() and (table["mhd_m"] > 0).all()
    assert table["height_rmse_m"].iloc[:2].notna().all()
    assert table["completeness"].between(0, 1).all()
    plot = realdata_plot.fronts_figure(table)
    assert plot is not None and len(plot.figure.axes) == len(realdata_plot.FRONT_PANELS)
    assert isinstance(table, pd.DataFrame) and set(table["terrain"]) == {"balm_seq"}
