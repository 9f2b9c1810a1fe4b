"""Tests of the map plot helpers (matplotlib Agg and pyvista off-screen)."""

from __future__ import annotations

import matplotlib as mpl
import numpy as np
import pytest

mpl.use("Agg")
import matplotlib.pyplot as plt

from alte.lab.plot.maps import (
    QUADTREE_TIMELAPSE,
    UNKNOWN_COLOR,
    add_cells_3d,
    add_timelapse_3d,
    cells_mesh,
    plot_basis_functions_over_time,
    plot_map_2d,
    plot_timelapse_2d,
)
from alte.mappers.base import Cells


def cells_2d() -> Cells:
    """Four 1 m cells: ground, obstacle, unknown, ground."""
    centers = np.array([[0.5, 0.5, 0.0], [1.5, 0.5, 3.0], [0.5, 1.5, np.nan], [1.5, 1.5, 0.1]])
    sizes = np.array([[1.0, 1.0, 0.0]] * 4)
    value = centers[:, 2].copy()
    occupied = np.array([False, True, False, False])
    return Cells(centers, sizes, value, occupied, np.ones(4, np.int64))


def cells_3d() -> Cells:
    centers = np.array([[0.5, 0.5, 0.5], [1.5, 0.5, 1.0], [0.5, 1.5, 0.25]])
    sizes = np.array([[1.0, 1.0, 1.0], [1.0, 1.0, 2.0], [0.5, 0.5, 0.5]])
    return Cells(centers, sizes, np.array([0.9, 0.8, 0.2]), np.array([True, True, False]),
                 np.array([1, 1, 2]))


def test_plot_map_2d_segments_and_occupancy() -> None:
    fig, (left, right) = plt.subplots(1, 2)
    seg, occ = plot_map_2d(cells_2d(), left, right, title="demo")
    assert len(seg.get_paths()) == 4 and len(occ.get_paths()) == 4
    faces = seg.get_facecolor()
    assert np.allclose(faces[2], UNKNOWN_COLOR)
    assert not np.allclose(faces[0], faces[1])  # heights 0 and 3 differ in colour
    occ_faces = occ.get_facecolor()
    assert np.allclose(occ_faces[1], (0, 0, 0, 1)) and np.allclose(occ_faces[0], (1, 1, 1, 1))
    assert np.allclose(occ_faces[2], UNKNOWN_COLOR)
    assert left.get_xlim() == (0.0, 2.0) and "segments" in left.get_title()
    plt.close(fig)


def test_plot_map_2d_occupancy_from_heights() -> None:
    fig, (left, right) = plt.subplots(1, 2)
    _seg, occ = plot_map_2d(cells_2d(), left, right, height_threshold=0.05)
    faces = occ.get_facecolor()
    black = np.all(np.isclose(faces, (0, 0, 0, 1)), axis=1)
    assert black.tolist() == [False, True, False, True]  # 3.0 and 0.1 m rise over 0.05 m
    assert np.allclose(faces[2], UNKNOWN_COLOR)
    _seg, occ = plot_map_2d(cells_2d(), left, right, height_threshold=0.05, ground=0.5)
    assert np.all(np.isclose(occ.get_facecolor(), (0, 0, 0, 1)), axis=1).sum() == 1
    plt.close(fig)


def test_plot_map_2d_without_occupancy_and_all_unknown() -> None:
    fig, ax = plt.subplots()
    c = cells_2d()
    unknown = Cells(c.centers * [1, 1, np.nan], c.sizes, c.value * np.nan,
                    np.zeros(4, bool), c.level)
    seg, occ = plot_map_2d(unknown, ax)
    assert occ is None and np.allclose(seg.get_facecolor(), UNKNOWN_COLOR)
    plt.close(fig)


def test_cells_mesh_boxes_and_squares() -> None:
    mesh = cells_mesh(cells_3d())
    assert mesh.n_cells == 2
    assert np.allclose(mesh.bounds, (0.0, 2.0, 0.0, 1.0, 0.0, 2.0))
    assert np.allclose(sorted(mesh.cell_data["height"]), [1.0, 2.0])
    flat = cells_mesh(cells_2d(), occupied_only=False, color_by="level")
    assert flat.n_cells == 3  # the unknown cell is skipped
    assert np.allclose(flat.bounds[4:], (0.0, 3.0))
    assert cells_mesh(cells_2d(), occupied_only=True).n_cells == 1
    with pytest.raises(ValueError, match="color_by"):
        cells_mesh(cells_3d(), color_by="colour")


def test_add_cells_3d_renders_off_screen() -> None:
    pv = pytest.importorskip("pyvista")
    plotter = pv.Plotter(off_screen=True, window_size=[200, 150])
    mesh = add_cells_3d(plotter, cells_3d(), color_by="value")
    grids = [name for name in plotter.renderer.actors if name.startswith("UnstructuredGrid")]
    assert mesh.n_cells == 2 and len(grids) == 1
    empty = Cells(np.empty((0, 3)), np.empty((0, 3)), np.empty(0), np.empty(0, bool),
                  np.empty(0, np.int64))
    assert add_cells_3d(plotter, empty).n_cells == 0
    image = plotter.screenshot(None, return_img=True)
    assert image.shape[:2] == (150, 200) and image.std() > 0
    plotter.close()


def test_plot_basis_functions_over_time() -> None:
    fig, ax = plt.subplots()
    line = plot_basis_functions_over_time([0.0, 1.0, 2.0], [1, 4, 7], ax, label="alte2d")
    assert np.array_equal(line.get_ydata(), [1, 4, 7])
    assert ax.get_ylabel() == "basis functions" and ax.get_legend() is not None
    plt.close(fig)


def test_timelapse_figures() -> None:
    pv = pytest.importorskip("pyvista")
    from types import SimpleNamespace

    snaps = [SimpleNamespace(time=1.0, cells=cells_2d()),
             SimpleNamespace(time=2.5, cells=cells_3d())]
    fig = plot_timelapse_2d(snaps, title="demo", caption=QUADTREE_TIMELAPSE).figure
    assert len(fig.axes) >= 4 and "t = 2.5 s" in fig.axes[2].get_title()
    plt.close(fig)
    plotter = pv.Plotter(off_screen=True, shape=(1, 2), window_size=[300, 150])
    add_timelapse_3d(plotter, snaps, title="demo")
    plotter.subplot(0, 1)
    grids = [n for n in plotter.renderer.actors if n.startswith("UnstructuredGrid")]
    assert len(grids) == 1
    plotter.close()
