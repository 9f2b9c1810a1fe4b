"""The command line's own words: plain text a terminal shows, no issue numbers, no drift."""

from __future__ import annotations

import argparse
import re

import pytest

from alte.cli import COMMANDS, full_parser
from bench.catalog import TITLES
from bench.runner import ROWS

# reStructuredText / Markdown a terminal would show raw, Python reprs, tracker references.
_MARKUP = re.compile(r"``|`|:(func|data|class|mod|meth|attr|ref|doc):|\{'|\bissue\b",
                     re.IGNORECASE)


def _subparsers(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    action = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return dict(action.choices)


@pytest.fixture(scope="module")
def helps() -> dict[str, str]:
    parser = full_parser()
    texts = {"alte": parser.format_help()}
    texts.update({name: sub.format_help() for name, sub in _subparsers(parser).items()})
    return texts


def test_every_command_is_registered_and_helped(helps: dict[str, str]) -> None:
    assert set(helps) == {"alte", *COMMANDS}


@pytest.mark.parametrize("name", ["alte", *COMMANDS])
def test_help_is_plain_text(helps: dict[str, str], name: str) -> None:
    assert _MARKUP.findall(helps[name]) == []


def test_the_markup_check_can_fail() -> None:
    said = "Command-line entry point: ``alte COMMAND ...`` (issue 6), defaults {'a': 1}"
    assert len(_MARKUP.findall(said)) == 4


def test_bench_help_lists_the_rows_that_exist(helps: dict[str, str]) -> None:
    assert set(TITLES) == set(ROWS)  # one registry of rows, titles and functions alike
    text = helps["bench"]
    for number, title in TITLES.items():
        assert f"- row {number}: {title}" in text
    assert f"all, {min(TITLES)}-{max(TITLES)}" in " ".join(text.split())


def test_bench_outside_a_checkout_says_where_the_benchmark_lives(tmp_path) -> None:
    from alte.commands import bench as command
    from alte.errors import AlteError

    with pytest.raises(AlteError, match="alte bench runs from a source checkout: no bench/"):
        command._find_bench(tmp_path)
