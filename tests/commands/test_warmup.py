"""Tests for ``alte warmup``: every mapper and feed maps the short flight."""

from __future__ import annotations

import re

from alte.cli import main
from alte.mappers import Feed, registry
from alte.mappers.quad import treebuild as _treebuild
from alte.metrics import _gridnn


def test_every_mapper_and_feed_maps_the_flight(capsys):
    assert main(["warmup"]) == 0
    out = capsys.readouterr().out
    count = len(registry.classes())
    assert out.startswith(f"compiled and cached the kernels of {count} mappers in ")
    cells = dict(re.findall(r"(\w+/\w+) (\d+)", out))
    flights = {f"{name}/{feed.value}" for name in registry.names() for feed in Feed}
    clouds = {f"{kind.name}/cloud" for kind in registry.classes() if kind.dims == 2}
    assert set(cells) == flights | clouds
    assert all(int(n) > 0 for n in cells.values()), cells
    assert _gridnn._query.signatures  # the grid search of HD/MHD is compiled too
    assert _treebuild._walk_groups.signatures  # and the tree walk of a whole cloud
