"""The mapper protocol's shared pieces: point checks, the registry, capabilities, export."""

from pathlib import Path

import numpy as np
import pytest

from alte.errors import MapperError
from alte.mappers import (
    CellCounts,
    Cost,
    Domain,
    DomainUse,
    Feed,
    Mapper,
    check_export,
    make_mapper,
    registry,
)
from alte.mappers.base import check_points

#: The thesis' four by name.
BUILTIN = {cls.name: cls for cls in registry.BUILTIN}


def test_check_points():
    pts = check_points([[0, 0, 0], [1, 2, 3]], "quadtree")
    assert pts.dtype == np.float64
    with pytest.raises(MapperError, match=r"quadtree: points must have shape \(N, 3\)"):
        check_points(np.zeros((3, 2)), "quadtree")
    with pytest.raises(MapperError, match="NaN or inf"):
        check_points([[0, np.nan, 0]], "quadtree")


@pytest.mark.parametrize("name", list(BUILTIN))
def test_every_mapper_declares_its_capabilities(name):
    cls = registry.resolve(name)
    mapper = make_mapper(name)
    assert isinstance(mapper, Mapper)
    assert cls.dims in (2, 3) and isinstance(cls.incremental, bool)
    assert isinstance(cls.domain_use, DomainUse) and isinstance(cls.default_feed, Feed)
    assert ".npz" in cls.exports and isinstance(cls.free_space, bool)
    assert mapper.points_outside == 0 and mapper.params == cls.Settings()
    assert isinstance(cls.cost_unit, Cost) and mapper.cost == 0


def test_capabilities_of_the_four_mappers():
    assert BUILTIN["quadtree"].default_feed is Feed.BATCH
    assert BUILTIN["octomap"].domain_use is DomainUse.UNUSED and BUILTIN["octomap"].free_space
    assert BUILTIN["alte3d"].domain_use is DomainUse.REQUIRED
    assert BUILTIN["alte2d"].domain_use is DomainUse.OPTIONAL
    assert ".bt" in BUILTIN["octomap"].exports and ".bt" not in BUILTIN["alte3d"].exports


def test_unknown_mapper_and_exports(tmp_path: Path):
    with pytest.raises(MapperError, match="unknown mapper 'octree'; valid: quadtree, octomap"):
        make_mapper("octree")
    with pytest.raises(MapperError, match=r"mapper 'alte3d' writes \.npz \(not \.bt\)"):
        check_export(tmp_path / "map.bt", BUILTIN["alte3d"], overwrite=False)
    with pytest.raises(MapperError, match="no native map format"):
        make_mapper("quadtree").write_native(tmp_path / "x.bt")
    with pytest.raises(MapperError, match="takes no domain"):
        from alte.mappers import Domain

        make_mapper("octomap", domain=Domain(0, 0, 0, 1))


@pytest.mark.parametrize("name", list(BUILTIN))
def test_cell_counts_equal_the_cells_table(name):
    """``cell_counts`` (what ``alte map --json`` prints) counts what ``cells()`` holds."""
    rng = np.random.default_rng(3)
    points = np.column_stack([rng.uniform(0, 20, (3000, 2)), rng.uniform(0, 2, 3000)])
    points[:200, 2] += 4.0  # an obstacle, so some cells are occupied and some are not
    params = {"octomap": {"resolution": 2.0},
              "alte3d": {"min_pts": 2, "occupancy_level": 0}}.get(name, {})
    text = {2: "0,0,20", 3: "0,0,-2,24"}[registry.resolve(name).dims]
    domain = None if name == "octomap" else Domain.parse(text)
    mapper = make_mapper(name, params, domain=domain)
    mapper.build(points, np.array([10.0, 10.0, 20.0]))
    cells = mapper.cells()
    counts = mapper.cell_counts()
    assert counts == CellCounts(len(cells), int(np.count_nonzero(cells.occupied)))
    assert 0 < counts.occupied <= counts.cells


def test_octomap_counts_ray_steps_and_end_voxels():
    # 1 m voxels: a ray 10 voxels along x steps through 10, a diagonal one through 3+2+1
    mapper = make_mapper("octomap", {"resolution": 1.0})
    origin = np.array([0.5, 0.5, 0.5])
    mapper.insert(np.array([[10.5, 0.5, 0.5]]), origin)
    assert mapper.cost == 10 + 1
    mapper.insert(np.array([[3.5, 2.5, 1.5], [0.6, 0.6, 0.6]]), origin)  # second: no step
    assert mapper.cost == 11 + (6 + 1) + (0 + 1)
    finer = make_mapper("octomap", {"resolution": 2.0})
    finer.insert(np.array([[10.5, 0.5, 0.5]]), origin)
    assert finer.cost == 20 + 1
    mapper.build(np.array([[10.5, 0.5, 0.5]]), origin)  # a build starts afresh
    assert mapper.cost == 11


@pytest.mark.parametrize("name", ["quadtree", "alte2d", "alte3d"])
def test_tree_maps_count_points_and_cell_updates(name):
    # 50 points in one finest cell: each is located, and one cell per level is written
    depth = {"quadtree": 12, "alte2d": 6, "alte3d": 6}[name]
    text = {2: "0,0,64", 3: "0,0,0,64"}[registry.resolve(name).dims]
    points = np.full((50, 3), 0.1) + np.linspace(0, 0.001, 50)[:, None]
    mapper = make_mapper(name, {"max_points": 10} if name == "quadtree" else {},
                         domain=Domain.parse(text))
    mapper.insert(points, np.zeros(3))
    assert mapper.cost == 50 + depth + 1
    mapper.insert(points, np.zeros(3))
    assert mapper.cost == 2 * (50 + depth + 1)
    mapper.build(points)  # a build starts afresh (a Quadtree's: the partition's cells only)
    assert mapper.cost == 50 + depth + 1


def test_the_cost_follows_the_work_not_the_machine():
    rng = np.random.default_rng(5)
    points = np.column_stack([rng.uniform(0, 30, (4000, 2)), rng.uniform(0, 3, 4000)])
    costs = []
    for _ in range(2):
        mapper = make_mapper("alte2d", {"max_res": 5}, domain=Domain.parse("0,0,32"))
        for part in np.array_split(points, 4):
            mapper.insert(part, np.zeros(3))
        costs.append(mapper.cost)
    deeper = make_mapper("alte2d", {"max_res": 7}, domain=Domain.parse("0,0,32"))
    deeper.build(points)
    assert costs[0] == costs[1] and deeper.cost > costs[0] > len(points)
