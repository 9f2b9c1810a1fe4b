"""Run order for ``make test`` (``pytest -n 2 --dist loadfile --no-loadscope-reorder``).

xdist hands whole files to the two workers, one at a time as each runs dry, in the
collection order (``--no-loadscope-reorder``: its default orders files by their number
of tests, which says little about time). A long file handed out last leaves one core
idle while the other finishes it, so files holding a ``slow`` test and the notebooks go
first; the many short files then fill both workers to the end. Within a file the order
stays.
"""

from __future__ import annotations

import pytest


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """Long files first (stable: files and their tests keep their relative order)."""
    long_files = {item.path for item in items
                  if item.get_closest_marker("slow") or item.path.suffix == ".ipynb"}
    items.sort(key=lambda item: item.path not in long_files)


def pytest_addoption(parser: pytest.Parser) -> None:
    """``--update-reference``: rewrite tests/reference's expected tables from this run
    (``make reference``; a deliberate change whose diff a reviewer reads)."""
    parser.addoption("--update-reference", action="store_true", default=False,
                     help="rewrite the expected tables of tests/reference from this run")
