"""The ground filters scored on real terrain (alte.lab.studies.realdata.filters): the tables on
a synthetic folder, and the acceptance test on the real ISPRS samples and ALS tiles: the
ground stage's default at least as good as SMRF with its published parameters."""

from __future__ import annotations

from pathlib import Path

import laspy
import numpy as np
import pytest
from ground.test_filters import slope_with_objects

from alte.errors import ParameterError
from alte.io import write_points
from alte.lab.studies import realdata
from alte.paths import realdata_dir

REALDATA = realdata_dir()


@pytest.fixture
def fake_root(tmp_path: Path) -> Path:
    """One ISPRS-like sample and one ALS tile (class 2 ground, a noise point) on disk."""
    points, ground = slope_with_objects(size=30.0)
    folder = tmp_path / "realdata"
    write_points(folder / "isprs_terrain" / "samp99-utm.pcd", points)
    write_points(folder / "isprs_terrain" / "samp99-utm-ground.pcd", points[ground])
    header = laspy.LasHeader(point_format=6, version="1.4")
    header.scales = np.full(3, 0.001)
    las = laspy.LasData(header)
    noisy = np.vstack([points, [[10.0, 10.0, -50.0]]])
    las.x, las.y, las.z = noisy.T
    las.classification = np.r_[np.where(ground, 2, 1), 7].astype(np.uint8)
    (folder / "als" / "sub").mkdir(parents=True)
    las.write(folder / "als" / "sub" / "tile.las")
    return folder


def test_tables_on_a_synthetic_folder(fake_root: Path) -> None:
    data = realdata.locate(fake_root)
    assert realdata.als_tiles(data) == ("sub/tile.las",)
    tile = realdata.als_tile(data, "sub/tile.las")
    assert len(tile.points) == len(slope_with_objects(size=30.0)[0])  # noise left out
    clouds = realdata.labelled_clouds(data)
    assert [(c.name, c.dataset) for c in clouds] == [("samp99", "isprs"),
                                                     ("sub/tile.las", "als")]
    candidates = ["default", "morph"]
    table = realdata.filter_table(clouds, candidates, progress=False)
    kappa = table.set_index("filter")["kappa_pct"]
    assert len(table) == 4 and (kappa["default"] > 95).all() and (kappa["morph"] > 50).all()
    assert table["settings"].iloc[0].startswith("cell=1.0, window=18.0, slope=0.1,")
    means = realdata.mean_table(table)
    assert means.set_index(["dataset", "filter"]).shape == (4, 5)
    chosen = realdata.choose(table, "isprs", "als")
    assert chosen["chosen"] in candidates and set(chosen["kappa_check"]) == set(candidates)
    with pytest.raises(ParameterError, match=r"ground filters \['tin'\] unknown; valid: "):
        realdata.filter_table(clouds, ["tin"])
    with pytest.raises(ParameterError, match="no data set 'lidar'"):
        realdata.choose(table, "lidar", "als")
    assert realdata.reference_gaps(tile) < 5.0  # this class 2 is complete
    assert realdata.labelled_clouds(realdata.locate(fake_root / "absent")) == []


#: The ALS tile `make test` checks beside every ISPRS sample: the drone survey (17,000
#: points), the platform this project maps from. The ISPRS samples, on which the default
#: was chosen, are what catches a worse default (slope 0.05 or 0.20, threshold 0.3 or
#: 1.0 m, window 9 m, cell 2 m, no slope scaling: each fails the ISPRS comparison); SMRF's
#: cost grows with a cloud's area, not its points (the sparse 38,000-point mountains cost
#: ten times the drone tile), so `make check-full` runs every cloud (about 55 CPU s).
QUICK_ALS = ("dji_l1_riparian.las",)


def _default_against_smrf(als: tuple[str, ...] | None) -> None:
    """The default's mean kappa at least SMRF's (published parameters) on each data set:
    every ISPRS sample and the ALS tiles ``als`` (None: all); only those are read."""
    clouds = realdata.labelled_clouds(realdata.locate(REALDATA), als=als)
    assert {c.dataset for c in clouds} == {"isprs", "als"}
    table = realdata.filter_table(clouds, ["default", "smrf published"], progress=False)
    means = realdata.mean_table(table).set_index(["dataset", "filter"])["kappa_pct"]
    for dataset in ("isprs", "als"):
        assert means[(dataset, "default")] >= means[(dataset, "smrf published")], means
    # the ISPRS samples: the band the papers report (SMRF 85-90 % over the 15 samples)
    assert means[("isprs", "default")] > 85.0


@pytest.mark.realdata
@pytest.mark.skipif(not REALDATA.is_dir(), reason="../shared/realdata absent")
def test_the_default_holds_against_published_smrf_on_the_small_clouds() -> None:
    """Side by side on every ISPRS sample and the drone survey's tile."""
    _default_against_smrf(als=QUICK_ALS)


@pytest.mark.full
@pytest.mark.realdata
@pytest.mark.skipif(not REALDATA.is_dir(), reason="../shared/realdata absent")
def test_the_default_holds_against_published_smrf_on_both_data_sets() -> None:
    """Side by side on every ISPRS sample and every ALS tile (whole)."""
    _default_against_smrf(als=None)
