"""The mapper protocol's shared pieces: point checks, the registry, capabilities, export."""

from pathlib import Path

import numpy as np
import pytest

from alte.errors import MapperError
from alte.mappers import (
    MAPPERS,
    CellCounts,
    Domain,
    DomainUse,
    Feed,
    Mapper,
    check_export,
    make_mapper,
    mapper_class,
)
from alte.mappers.base import check_points


def test_check_points():
    pts = check_points([[0, 0, 0], [1, 2, 3]], "quadtree")
    assert pts.dtype == np.float64
    with pytest.raises(MapperError, match=r"quadtree: points must have shape \(N, 3\)"):
        check_points(np.zeros((3, 2)), "quadtree")
    with pytest.raises(MapperError, match="NaN or inf"):
        check_points([[0, np.nan, 0]], "quadtree")


@pytest.mark.parametrize("name", list(MAPPERS))
def test_every_mapper_declares_its_capabilities(name):
    cls = mapper_class(name)
    mapper = make_mapper(name)
    assert isinstance(mapper, Mapper)
    assert cls.dims in (2, 3) and isinstance(cls.incremental, bool)
    assert isinstance(cls.domain_use, DomainUse) and isinstance(cls.default_feed, Feed)
    assert ".npz" in cls.exports and isinstance(cls.free_space, bool)
    assert mapper.points_outside == 0 and mapper.params == cls.Params()


def test_capabilities_of_the_four_mappers():
    assert MAPPERS["quadtree"].default_feed is Feed.BATCH
    assert MAPPERS["octomap"].domain_use is DomainUse.UNUSED and MAPPERS["octomap"].free_space
    assert MAPPERS["alte3d"].domain_use is DomainUse.REQUIRED
    assert MAPPERS["alte2d"].domain_use is DomainUse.OPTIONAL
    assert ".bt" in MAPPERS["octomap"].exports and ".bt" not in MAPPERS["alte3d"].exports


def test_unknown_mapper_and_exports(tmp_path: Path):
    with pytest.raises(MapperError, match="unknown mapper 'octree'; valid: quadtree, octomap"):
        make_mapper("octree")
    with pytest.raises(MapperError, match=r"mapper 'alte3d' writes \.npz \(not \.bt\)"):
        check_export(tmp_path / "map.bt", MAPPERS["alte3d"], overwrite=False)
    with pytest.raises(MapperError, match="no native map format"):
        make_mapper("quadtree").write_native(tmp_path / "x.bt")
    with pytest.raises(MapperError, match="takes no domain"):
        from alte.mappers import Domain

        make_mapper("octomap", domain=Domain(0, 0, 0, 1))


@pytest.mark.parametrize("name", list(MAPPERS))
def test_cell_counts_equal_the_cells_table(name):
    """``cell_counts`` (what ``alte map --json`` prints) counts what ``cells()`` holds."""
    rng = np.random.default_rng(3)
    points = np.column_stack([rng.uniform(0, 20, (3000, 2)), rng.uniform(0, 2, 3000)])
    points[:200, 2] += 4.0  # an obstacle, so some cells are occupied and some are not
    params = {"octomap": {"resolution": 2.0},
              "alte3d": {"min_pts": 2, "occupancy_level": 0}}.get(name, {})
    text = {2: "0,0,20", 3: "0,0,-2,24"}[mapper_class(name).dims]
    domain = None if name == "octomap" else Domain.parse(text)
    mapper = make_mapper(name, params, domain=domain)
    mapper.build(points, np.array([10.0, 10.0, 20.0]))
    cells = mapper.cells()
    counts = mapper.cell_counts()
    assert counts == CellCounts(len(cells), int(np.count_nonzero(cells.occupied)))
    assert 0 < counts.occupied <= counts.cells
