"""Where the front page's words come from: chapter titles, figure captions, key tables.

A figure's caption is declared beside the code that draws it (:mod:`alte.lab.plot`, each
figure a :class:`~alte.lab.plot.figure.Plot` or :class:`~alte.lab.plot.figure.View` holding its
:class:`~alte.lab.plot.figure.Caption`) and saved beside its PNG as ``figures/NAME.json``.
:func:`caption` picks, in this order:

1. the notebook's own ``results.json`` key ``"captions"``: ``{figure name: text}``, for a
   caption that depends on the run (a notebook captions what only it knows);
2. the caption saved beside the figure, its ``{TERRAIN}``-style fields filled from the
   run's parameters;
3. otherwise (a PNG saved by something other than alte) the figure name in words,
   marked "no caption".

Figures named with a prefix of :data:`TRADEOFF_PREFIXES` are shown in the front page's
trade-off section rather than under their chapter.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

from alte.lab.entry import KeyTable
from alte.lab.plot.figure import Caption, SavedCaption, fill, read_caption
from alte.lab.report.plan import PLAN
from alte.lab.studies.sensor import report as sensor
from alte.lab.studies.thesis import report as thesis
from alte.lab.studies.tradeoff import report as tradeoff
from alte.types import JSONMap

__all__ = ["CHAPTERS", "KEY_TABLES", "TRADEOFF_PREFIXES", "Caption", "KeyTable", "caption",
           "chapter_title", "saved_figures"]

#: Figure-name prefixes of the trade-off figures (see :mod:`alte.lab.studies.tradeoff.figures`).
TRADEOFF_PREFIXES = ("tradeoff", "equal_size", "equal_fidelity")
#: Sort rank of a figure saved without a caption (after every captioned one).
_UNSAVED = 1 << 62


#: Chapter title per source notebook stem (each study's :attr:`Entry.title`).
CHAPTERS: dict[str, str] = {Path(e.notebook).stem: e.title for e in PLAN if e.title}

#: The key tables of every study, in the order the front page shows them.
KEY_TABLES: tuple[KeyTable, ...] = tuple(sorted(
    (*tradeoff.KEY_TABLES, *sensor.KEY_TABLES, *thesis.KEY_TABLES), key=lambda k: k.rank))


def chapter_title(notebook: str, run_name: str, parameters: JSONMap) -> str:
    """The title of a run's section: its chapter's title, or the run name."""
    template = CHAPTERS.get(notebook)
    if template is None:
        return run_name.replace("_", " ")
    return fill(template, parameters)


def caption(figure: str, saved: SavedCaption | None, parameters: JSONMap,
            own: Mapping[str, object] | None = None) -> Caption:
    """The caption of ``figure`` (its PNG's stem) from the notebook's own captions
    (``own``), else the one ``saved`` beside it (see the module docstring)."""
    title = saved.caption.title if saved else figure.replace("_", " ")
    text = own.get(figure) if own else None
    if isinstance(text, str) and text.strip():
        return Caption(title, text)
    if saved:
        return saved.caption.filled(parameters)
    return Caption(title, "(no caption)")


def saved_figures(folder: Path) -> list[tuple[Path, SavedCaption | None]]:
    """The PNGs in ``folder`` with the captions saved beside them: trade-off prefixes
    first (in the order of :data:`TRADEOFF_PREFIXES`), each group in the order the
    figures were saved, figures without a caption last."""
    saved = {png: read_caption(png) for png in (folder.glob("*.png") if folder.is_dir() else [])}

    def order(png: Path) -> tuple[int, int, str]:
        prefix = next((i for i, p in enumerate(TRADEOFF_PREFIXES) if png.stem.startswith(p)),
                      -1)
        known = saved[png]
        return prefix, _UNSAVED if known is None else known.order, png.stem

    return [(png, saved[png]) for png in sorted(saved, key=order)]
