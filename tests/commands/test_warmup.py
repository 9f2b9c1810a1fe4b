"""Tests for ``alte warmup``: every mapper and feed maps the short flight, and every numba
kernel of alte and its plugins is compiled (what ``alte report`` relies on)."""

from __future__ import annotations

import importlib
import re
from pathlib import Path

import pytest
from numba.core.registry import CPUDispatcher

from alte.cli import main
from alte.mappers import Feed, registry
from alte.mappers.quad import treebuild as _treebuild
from alte.metrics import _gridnn

ROOT = Path(__file__).resolve().parents[2]
#: Where alte's kernels live: the package and the plugins shipped beside it.
PACKAGES = (ROOT / "alte", *sorted((ROOT / "plugins").glob("*/alte_*")))


@pytest.fixture(scope="module")
def warmed() -> str:
    """``alte warmup``'s output (run once for the module's tests)."""
    import contextlib
    import io

    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        assert main(["warmup"]) == 0
    return out.getvalue()


def test_every_mapper_and_feed_maps_the_flight(warmed: str) -> None:
    count = len(registry.classes())
    assert warmed.startswith(f"compiled and cached the kernels of {count} mappers in ")
    cells = dict(re.findall(r"(\w+/\w+) (\d+)", warmed))
    flights = {f"{name}/{feed.value}" for name in registry.names() for feed in Feed}
    clouds = {f"{kind.name}/cloud" for kind in registry.classes() if kind.dims == 2}
    assert set(cells) == flights | clouds
    assert all(int(n) > 0 for n in cells.values()), cells
    assert _gridnn._query.signatures  # the grid search of HD/MHD is compiled too
    assert _treebuild._walk_groups.signatures  # and the tree walk of a whole cloud


def _kernel_modules() -> list[str]:
    """Every module of alte and its plugins whose source declares a numba kernel."""
    names = []
    for package in PACKAGES:
        for path in sorted(package.rglob("*.py")):
            if "numba.njit" in path.read_text():
                parts = path.relative_to(package.parent).with_suffix("").parts
                names.append(".".join(parts[:-1] if parts[-1] == "__init__" else parts))
    return names


def _cached(kernel: CPUDispatcher) -> bool:
    """Whether numba's cache holds a compiled signature of ``kernel`` for its current
    source (a kernel called only from other kernels is compiled, and cached, with them)."""
    return bool(kernel.signatures) or bool(kernel._cache._cache_file._load_index())


def test_every_kernel_is_compiled(warmed: str) -> None:
    """A kernel added without a warmup path would be compiled by each notebook and worker
    of the report again: every kernel that is not inlined is in the cache after it."""
    kernels = {}
    for name in _kernel_modules():
        module = importlib.import_module(name)
        kernels |= {f"{name}.{key}": value for key, value in vars(module).items()
                    if isinstance(value, CPUDispatcher) and value.py_func.__module__ == name}
    assert len(kernels) > 60, sorted(kernels)
    cold = sorted(name for name, kernel in kernels.items()
                  if kernel.targetoptions.get("inline") != "always" and not _cached(kernel))
    assert not cold, f"kernels alte warmup does not compile: {cold}"


def test_a_part_compiles_its_share_of_the_mappers(warmed: str,
                                                  capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["warmup", "--part", "2/2"]) == 0
    out = capsys.readouterr().out
    share = registry.names()[1::2]
    assert f"kernels of {len(share)} mappers (part 2 of 2) in " in out
    assert {run.split("/")[0] for run in re.findall(r"(\w+)/\w+ \d+", out)} == set(share)


@pytest.mark.parametrize("bad", ["0/2", "3/2", "2", "a/b", "1/0"])
def test_a_bad_part_names_the_flag(bad: str, capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit, match="2"):
        main(["warmup", "--part", bad])
    assert re.search(r"argument --part: expected K/N with 1 <= K <= N, got '"
                     + re.escape(bad) + "'", capsys.readouterr().err)
