"""A figure with its caption: what every figure-building function of :mod:`alte.lab.plot` returns.

A :class:`Caption` (short title and text) is declared beside the code that draws the
figure; :class:`Plot` (a matplotlib ``Figure``) and :class:`View` (a pyvista ``Plotter``)
carry it to :func:`alte.lab.plot.render.save_figure`, the one way figures are saved, which
writes ``figures/NAME.png`` and, beside it, the caption sidecar ``figures/NAME.json``
(:func:`write_caption`: title, text template, save order). The report reads the sidecar
(:func:`read_caption`) and fills the text's ``{NAME}`` fields from the run's parameters
(:meth:`Caption.filled`), so a figure and its words cannot drift apart.
"""

from __future__ import annotations

import io
import json
import os
import re
import string
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from alte.errors import ParameterError
from alte.fsutil import atomic_path

if TYPE_CHECKING:
    import pyvista as pv
    from matplotlib.figure import Figure

__all__ = [
    "Caption",
    "Plot",
    "SavedCaption",
    "View",
    "figure_path",
    "fill",
    "read_caption",
    "write_caption",
]

#: Resolution of saved and displayed figures (dots per inch).
DPI = 110


@dataclass(frozen=True)
class Caption:
    """A figure's short title and its caption text; the text may hold ``{NAME}`` fields
    (a run parameter such as ``{TERRAIN}``), filled when the report shows it."""

    title: str
    text: str

    def __post_init__(self) -> None:
        for name in ("title", "text"):
            value = getattr(self, name)
            if not isinstance(value, str) or not value.strip():
                raise ParameterError(f"caption {name} {value!r}: expected non-empty text")
        try:
            fields = [f for _, f, _, _ in string.Formatter().parse(self.text) if f is not None]
        except ValueError as err:
            raise ParameterError(f"caption {self.title!r}: text {self.text!r} is no "
                                 f"template ({err})") from err
        if not all(f.isidentifier() for f in fields):
            raise ParameterError(f"caption {self.title!r}: fields {fields} must be names "
                                 "such as {TERRAIN}")

    def filled(self, parameters: Mapping[str, object]) -> Caption:
        """The caption with its fields filled from ``parameters`` (see :func:`fill`)."""
        return Caption(self.title, fill(self.text, parameters) or "(no caption)")


class _Fields(dict[str, str]):
    def __missing__(self, key: str) -> str:
        return ""


def fill(text: str, parameters: Mapping[str, object]) -> str:
    """``text`` with ``{NAME}`` fields from ``parameters``; a missing field is dropped with
    the preposition before it ("cloud of {TERRAIN}." -> "cloud.")."""
    values = _Fields({k: str(v) for k, v in parameters.items()})
    filled = string.Formatter().vformat(text, (), values)
    filled = re.sub(r"\s+(?:of|on|in|for|over)?\s*(?=[.,;:]|$)", "", filled)
    return re.sub(r"\s{2,}", " ", filled).strip()


@dataclass(frozen=True, eq=False)
class Plot:
    """A matplotlib figure and its caption (a notebook displays it as the figure's PNG)."""

    figure: Figure
    caption: Caption

    def png(self) -> bytes:
        """The figure as PNG bytes. A figure with constrained layout already fits its
        canvas; trimming it to a tight box as well would draw it twice (the layout solved
        each time), so only others are trimmed.

        The bytes are kept until the figure changes: a notebook saves a figure and then
        shows it, and drawing it twice cost a report about a minute of CPU. Drawing
        leaves the figure marked stale (the tight box resizes it and back), so it is
        marked fresh here; any later change to one of its artists marks it stale again,
        and it is drawn anew."""
        from matplotlib.layout_engine import ConstrainedLayoutEngine

        drawn = self.__dict__.get("_drawn")
        if isinstance(drawn, bytes) and not self.figure.stale:
            return drawn
        tight = not isinstance(self.figure.get_layout_engine(), ConstrainedLayoutEngine)
        buffer = io.BytesIO()
        self.figure.savefig(buffer, format="png", dpi=DPI,
                            bbox_inches="tight" if tight else None, metadata={"Software": None})
        self.figure.stale = False
        object.__setattr__(self, "_drawn", buffer.getvalue())  # a memo, not a field
        return buffer.getvalue()

    def _repr_png_(self) -> bytes:
        return self.png()


@dataclass(frozen=True, eq=False)
class View:
    """A pyvista plotter (a 3D view) and its caption."""

    plotter: pv.Plotter
    caption: Caption


@dataclass(frozen=True)
class SavedCaption:
    """A saved figure's caption (text template, fields unfilled) and its save order in
    its folder (0 first)."""

    caption: Caption
    order: int


def figure_path(out_dir: str | os.PathLike[str], name: str) -> Path:
    """``out_dir/figures/name.png``; ``name`` must be a plain file stem."""
    if not name or not re.fullmatch(r"[\w.-]+", name) or name.startswith("."):
        raise ParameterError(f"figure name {name!r}: expected a file stem of letters, digits, "
                             "'_', '-' or '.'")
    return Path(out_dir) / "figures" / f"{name}.png"


def _order(png: Path) -> int:
    """The save order of ``png``: its earlier one when saved before, else the next."""
    earlier = read_caption(png)
    if earlier is not None:
        return earlier.order
    saved = [read_caption(p.with_suffix(".png")) for p in png.parent.glob("*.json")]
    return 1 + max((s.order for s in saved if s is not None), default=-1)


def write_caption(png: Path, caption: Caption) -> Path:
    """Write ``caption`` beside ``png`` as ``<stem>.json`` (title, text, order; atomic)."""
    path = png.with_suffix(".json")
    record = {"title": caption.title, "text": caption.text, "order": _order(png)}
    with atomic_path(path, overwrite=True) as tmp:
        tmp.write_text(json.dumps(record, indent=2, sort_keys=True) + "\n", encoding="utf-8")
    return path


def read_caption(png: Path) -> SavedCaption | None:
    """The caption saved beside ``png``, or None when there is none or it is unreadable."""
    try:
        data = json.loads(png.with_suffix(".json").read_text(encoding="utf-8"))
        title, text, order = data["title"], data["text"], data["order"]
    except (OSError, ValueError, TypeError, KeyError):
        return None
    if not (isinstance(title, str) and isinstance(text, str) and isinstance(order, int)):
        return None
    try:
        return SavedCaption(Caption(title, text), order)
    except ParameterError:
        return None
