"""Where the front page's words come from: chapter titles, figure captions, key tables.

A figure's caption is declared beside the code that draws it (:mod:`alte.plot`, each
figure a :class:`~alte.plot.figure.Plot` or :class:`~alte.plot.figure.View` holding its
:class:`~alte.plot.figure.Caption`) and saved beside its PNG as ``figures/NAME.json``.
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
from dataclasses import dataclass
from pathlib import Path

from alte.plot.figure import Caption, SavedCaption, fill, read_caption
from alte.types import JSONMap

__all__ = ["CHAPTERS", "KEY_TABLES", "TRADEOFF_PREFIXES", "Caption", "KeyTable", "caption",
           "chapter_title", "saved_figures"]

#: Figure-name prefixes of the trade-off figures (see :mod:`alte.plot.tradeoff`).
TRADEOFF_PREFIXES = ("tradeoff", "equal_size", "equal_fidelity")
#: Sort rank of a figure saved without a caption (after every captioned one).
_UNSAVED = 1 << 62


#: Chapter title per source notebook stem.
CHAPTERS: dict[str, str] = {
    "ch2_test_benchmark": "Chapter 2: the test benchmark on {TERRAIN}",
    "ch3_mapping_techniques": "Chapter 3: the four mapping techniques on {TERRAIN}",
    "ch4_terrain": "Chapter 4: terrain {TERRAIN}",
    "ch5_analysis": "Chapter 5: analysis",
    "ch6_real_data": "Chapter 6: real data",
    "ch7_sensitivity": "Beyond the thesis: parameter sensitivity",
    "ch7_landing": "Beyond the thesis: landing-site selection",
    "ch7_planning": "Beyond the thesis: path planning",
}

@dataclass(frozen=True)
class KeyTable:
    """A CSV shown on the front page with the thesis' values beside ours."""

    name: str
    title: str
    text: str
    key: bool = True
    hide: tuple[str, ...] = ()
    rows: int = 60


#: The key tables, in the order the front page shows them.
KEY_TABLES: tuple[KeyTable, ...] = (
    KeyTable("table_5_10", "Table 5.10: best 2D maps by the thesis' rule",
             "Each mapper's map picked from our sweep by the thesis' comparison rule, beside "
             "the thesis' choice. Times are CPU seconds known within their spread: maps "
             "the rule cannot separate within it are all shown (rule_pick: tie)."),
    KeyTable("table_5_11", "Table 5.11: best 3D maps by the thesis' rule",
             "Each mapper's map picked from our sweep by the thesis' comparison rule, beside "
             "the thesis' choice. Times are CPU seconds known within their spread: maps "
             "the rule cannot separate within it are all shown (rule_pick: tie)."),
    KeyTable("key_equal_size", "MHD at equal size",
             "The MHD each mapper reaches at 1,000 / 5,000 / 20,000 basis functions, read "
             "off its Pareto front (only where its maps reach that size); mean over seeds "
             "with the 95 % bootstrap interval. Every metric: equal_size.csv.", key=False),
    KeyTable("key_equal_fidelity", "Size at equal MHD",
             "The basis functions each mapper needs for the same MHD (three levels inside "
             "both fronts' range per terrain); mean over seeds with the 95 % bootstrap "
             "interval. Memory and time too: equal_fidelity.csv.", key=False),
    KeyTable("ablation", "Ablations: what moves the verdicts",
             "Each claim's verdict on the thesis' two sweep terrains, first for the grid as "
             "specified (base), then with one thing changed: map size counted as occupied "
             "cells (size_occupied: Octomap's free and 3D-ALTE's empty leaves not counted), "
             "only the thesis' six settings per mapper (thesis_rows), the root cell over "
             "the data (domain_data), set B of cell centres (set_b_centers) or of occupied "
             "2D cells only (set_b_occupied), Quadtree's occupancy by the highest point "
             "(occupancy_max), 3D-ALTE's min_pts as a plain count per leaf "
             "(min_pts_per_leaf), the realistic UAV sensor with recorded poses and deskew "
             "(uav_deskew) or with LiDAR-inertial odometry's poses (uav_lio). 'moves' lists "
             "the changes that move the verdict; the quotes are in the claims table above.",
             key=False, hide=("claim",), rows=80),
    KeyTable("sensor", "The realistic UAV sensor: poses and cloud per mission",
             "Per UAV mission and way of posing the scans: ATE (m and % of the path) and RPE "
             "(% per metre, 1 m segments) against the simulator's truth after rigid "
             "alignment, the registered cloud's mean distance to the true mesh, and the CPU "
             "time per scan (the pose step alone for odometry, as measured when the "
             "mission was aligned, also when its poses were read from the cache; CPU, not "
             "wall time, so that the machine's load does not enter): means over the "
             "simulation seeds ('seeds'), with the worst seed's ATE and mesh distance beside "
             "them. Thesis sensor: the instantaneous scan; UAV sensor: each firing at its own "
             "instant, per-point time, an IMU.",
             key=False),
    KeyTable("table_5_7", "Table 5.7: Quadtree sweep", "Our maps beside the thesis' rows."),
    KeyTable("table_5_8", "Table 5.8: Octomap sweep", "Our maps beside the thesis' rows."),
    KeyTable("table_5_9", "Table 5.9: 2D-ALTE sweep", "Our maps beside the thesis' rows."),
    KeyTable("table_5_12", "Table 5.12: 3D-ALTE sweep", "Our maps beside the thesis' rows."),
    KeyTable("table_5_5", "Table 5.5: point cloud for the 3D analysis",
             "Frames and points of our registered cloud beside the thesis'."),
    KeyTable("table_5_6", "Table 5.6: point cloud for the 2D analysis",
             "Frames and points of our registered cloud beside the thesis'."),
)


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
