"""Tests for ``alte warmup``: every mapper and feed maps the short flight."""

from __future__ import annotations

import re

from alte.cli import main
from alte.mappers import MAPPERS, Feed
from alte.metrics import _gridnn


def test_every_mapper_and_feed_maps_the_flight(capsys):
    assert main(["warmup"]) == 0
    out = capsys.readouterr().out
    assert out.startswith(f"compiled and cached the kernels of {len(MAPPERS)} mappers in ")
    cells = dict(re.findall(r"(\w+/\w+) (\d+)", out))
    assert set(cells) == {f"{name}/{feed.value}" for name in MAPPERS for feed in Feed}
    assert all(int(n) > 0 for n in cells.values()), cells
    assert _gridnn._query.signatures  # the grid search of HD/MHD is compiled too
