"""Small picklable figure draws for the tests of :func:`alte.lab.plot.render.save_figures`
(a spawned process imports this module, not a study's)."""

from __future__ import annotations

from alte.errors import ParameterError
from alte.lab.plot.figure import Caption, Plot


def line(values: tuple[float, ...], title: str) -> Plot:
    """``values`` as a line, captioned ``title``."""
    from matplotlib.figure import Figure

    figure = Figure(figsize=(3, 2))
    figure.add_subplot().plot(values)
    return Plot(figure, Caption(title, f"The values of {title}."))


def nothing(reason: str) -> Plot:
    """A figure that cannot be drawn: ``reason``."""
    raise ParameterError(reason)
