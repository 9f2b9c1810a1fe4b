"""A figure and its caption: saved together, or not at all; the caption read back."""

from __future__ import annotations

import json
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import pytest
from matplotlib.figure import Figure

from alte.errors import ParameterError
from alte.lab.plot.figure import Caption, Plot, read_caption
from alte.lab.plot.render import save_figure, save_figures, show, view


def _plot(title: str = "Line", text: str = "A line over {TERRAIN}.") -> Plot:
    fig = Figure(figsize=(2, 1.5))
    fig.add_subplot().plot([0, 1], [1, 0])
    return Plot(fig, Caption(title, text))


def test_a_figure_without_a_caption_cannot_be_saved(tmp_path: Path) -> None:
    with pytest.raises(ParameterError, match=r"save_figure\(\.\.\., 'line'\): got a Figure "
                       r"without a caption; save the Plot or View"):
        save_figure(_plot().figure, tmp_path, "line")  # type: ignore[arg-type]
    assert not tmp_path.joinpath("figures").exists()  # nothing written


@pytest.mark.parametrize(("title", "text", "message"), [
    ("", "text", r"caption title '': expected non-empty text"),
    ("Title", "  ", r"caption text '  ': expected non-empty text"),
    ("Title", "cloud of {TERRAIN", r"caption 'Title': text 'cloud of \{TERRAIN' is no template"),
    ("Title", "scan {0}", r"caption 'Title': fields \['0'\] must be names"),
])
def test_a_caption_needs_a_title_and_a_text_template(title: str, text: str,
                                                     message: str) -> None:
    with pytest.raises(ParameterError, match=message):
        Caption(title, text)


def test_a_figure_name_is_a_file_stem(tmp_path: Path) -> None:
    for name in ("../up", "", ".hidden", "a b"):
        with pytest.raises(ParameterError, match=r"figure name .*: expected a file stem"):
            save_figure(_plot(), tmp_path, name)


def test_the_caption_is_saved_beside_the_png_in_save_order(tmp_path: Path) -> None:
    for name in ("b_first", "a_second", "c_third"):
        path = save_figure(_plot(title=name), tmp_path, name)
        assert path == tmp_path / "figures" / f"{name}.png"
        assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    sidecar = json.loads((tmp_path / "figures" / "b_first.json").read_text())
    assert sidecar == {"title": "b_first", "text": "A line over {TERRAIN}.", "order": 0}
    orders = {n: read_caption(tmp_path / "figures" / f"{n}.png") for n in
              ("b_first", "a_second", "c_third")}
    assert {n: s.order for n, s in orders.items() if s} == {
        "b_first": 0, "a_second": 1, "c_third": 2}
    save_figure(_plot("Again", "Saved again."), tmp_path, "b_first")  # a rerun keeps its place
    again = read_caption(tmp_path / "figures" / "b_first.png")
    assert again is not None and (again.order, again.caption) == (
        0, Caption("Again", "Saved again."))


def test_a_missing_or_broken_sidecar_reads_as_no_caption(tmp_path: Path) -> None:
    png = save_figure(_plot(), tmp_path, "line")
    png.with_suffix(".json").write_text('{"title": "Line", "text": ""')
    assert read_caption(png) is None
    png.with_suffix(".json").write_text('{"title": "Line", "text": "", "order": 0}')
    assert read_caption(png) is None
    png.with_suffix(".json").unlink()
    assert read_caption(png) is None


def test_fields_are_filled_from_the_run_parameters() -> None:
    cloud = Caption("Registered cloud", "The registered point cloud of {TERRAIN}.")
    assert cloud.filled({"TERRAIN": "sim_lan_1"}) == Caption(
        "Registered cloud", "The registered point cloud of sim_lan_1.")
    assert cloud.filled({}).text == "The registered point cloud."  # the preposition goes too
    terrain = Caption("Terrain", "The simulated terrain {TERRAIN} and its control volume.")
    assert terrain.filled({"FRAMES": 40}).text == "The simulated terrain and its control volume."
    assert Caption("Only", "{TERRAIN}").filled({}).text == "(no caption)"


def test_a_plot_shows_as_its_png() -> None:
    plot = _plot()
    assert plot._repr_png_()[:8] == b"\x89PNG\r\n\x1a\n"


def test_a_saved_plot_is_shown_without_drawing_it_again_until_it_changes(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A notebook saves a figure, then shows it: one draw. A change to any of its artists
    after that is drawn (a stale PNG would show the figure as it was)."""
    plot = _plot()
    draws: list[object] = []
    savefig = plot.figure.savefig
    monkeypatch.setattr(plot.figure, "savefig",
                        lambda *a, **k: (draws.append(a), savefig(*a, **k))[1])
    saved = save_figure(plot, tmp_path, "line").read_bytes()
    assert plot._repr_png_() == saved and len(draws) == 1
    first = plot.png()
    plot.figure.axes[0].lines[0].set_ydata([0, 1])
    changed = plot.png()
    assert len(draws) == 2 and changed != first
    plot.figure.axes[0].set_title("now with a title")
    assert plot.png() != changed and len(draws) == 3
    fresh = _plot()
    fresh.figure.axes[0].lines[0].set_ydata([0, 1])
    fresh.figure.axes[0].set_title("now with a title")
    assert plot.png() == fresh.png()  # the same bytes as a figure drawn once
    assert len(draws) == 3


def test_a_view_is_saved_with_its_caption_and_closed(tmp_path: Path) -> None:
    pv = pytest.importorskip("pyvista")
    cube = view(Caption("Cube", "A cube."), window_size=(160, 120))
    cube.plotter.add_mesh(pv.Cube())
    assert show(cube, tmp_path, "cube") is None
    saved = read_caption(tmp_path / "figures" / "cube.png")
    assert saved is not None and saved.caption == Caption("Cube", "A cube.")
    assert cube.plotter.render_window is None  # static: closed once shown
    plotter = pv.Plotter(off_screen=True)
    with pytest.raises(ParameterError, match="got a Plotter without a caption"):
        save_figure(plotter, tmp_path, "bare")  # type: ignore[arg-type]
    plotter.close()


def test_figures_drawn_in_processes_are_the_same_files_in_the_same_order(tmp_path: Path,
                                                                          ) -> None:
    """``jobs=2`` (chapter 5's trade-off figures): every PNG byte for byte as one process
    draws it, the captions numbered in the figures' order (each process counting from the
    folder's captions would number them 0, 0, 1 ...), a figure not drawn said so."""
    from functools import partial

    from support.plots import line, nothing

    figures = [("a", partial(line, (0.0, 1.0), "a")), ("none", partial(nothing, "no data")),
               ("b", partial(line, (1.0, 0.0, 2.0), "b")), ("c", partial(line, (3.0,), "c"))]
    one = save_figures(figures, tmp_path / "one")
    two = save_figures(figures, tmp_path / "two", jobs=2)
    assert list(two) == list(one) == ["a", "none", "b", "c"]
    assert two["none"] == one["none"] == "not drawn: no data"
    for name in ("a", "b", "c"):
        png = [d / "figures" / f"{name}.png" for d in (tmp_path / "one", tmp_path / "two")]
        assert png[0].read_bytes() == png[1].read_bytes(), name
        assert read_caption(png[0]) == read_caption(png[1]), name
    assert [read_caption(tmp_path / "two" / "figures" / f"{k}.png").order
            for k in ("a", "b", "c")] == [0, 1, 2]

