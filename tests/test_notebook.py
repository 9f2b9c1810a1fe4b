import json

import numpy as np
import pytest

from alte.errors import ParameterError
from alte.lab import notebook


def test_save_results_is_json_with_numpy_values(tmp_path):
    path = notebook.save_results(tmp_path / "out", {"n": np.int64(3), "a": np.arange(2),
                                                    "x": np.float32(0.5), "p": tmp_path})
    data = json.loads(path.read_text())
    assert data == {"n": 3, "a": [0, 1], "x": 0.5, "p": str(tmp_path)}
    with pytest.raises(ParameterError, match="save_results: set values cannot be written as "
                       "JSON"):
        notebook.save_results(tmp_path / "bad", {"s": {1, 2}})
    assert not (tmp_path / "bad" / "results.json").exists()


def test_setup_static_and_bad_mode():
    assert notebook.setup("static") == "static"
    assert not notebook.interactive()
    with pytest.raises(ValueError, match="render mode 'web'"):
        notebook.setup("web")


def test_save_figure(tmp_path):
    notebook.setup("static")
    import matplotlib.pyplot as plt

    from alte.lab.plot.figure import Caption, Plot

    fig, ax = plt.subplots()
    ax.plot([0, 1], [1, 0])
    path = notebook.save_figure(Plot(fig, Caption("Line", "A line.")), tmp_path, "line")
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_offscreen_pyvista_render(tmp_path):
    notebook.setup("static")
    import pyvista as pv

    from alte.lab.plot import show, view
    from alte.lab.plot.figure import Caption

    cube = view(Caption("Cube", "A cube."), window_size=(160, 120))
    cube.plotter.add_mesh(pv.Cube())
    assert show(cube, tmp_path, "cube") is None  # a cell ending in show() prints nothing
    assert (tmp_path / "figures" / "cube.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
