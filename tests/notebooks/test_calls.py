"""What each notebook takes from alte exists, and each call it makes binds, without a kernel.

`make test` executes one chapter notebook under nbval (``ch4_terrain``); `make check-full`
executes all of them (``FULL_NOTEBOOKS`` in ``tests/conftest.py``). Between the two, this
check reads every notebook's code: each ``import``/``from ... import`` resolves, each
``name.attr.attr`` reached from an imported name exists, and each call of an imported
function or class binds its positional count and keyword names to the signature. So a
renamed function, module or keyword breaks `make test`, not only the full run.
"""

from __future__ import annotations

import ast
import importlib
import inspect
from pathlib import Path
from types import ModuleType

import nbformat
import pytest

from alte.paths import REPO_ROOT

NOTEBOOKS = sorted((REPO_ROOT / "notebooks").glob("*.ipynb"))


def _code(path: Path) -> ast.Module:
    """The notebook's code cells as one module (IPython magics left out)."""
    nb = nbformat.read(str(path), as_version=4)
    lines = [line for cell in nb.cells if cell.cell_type == "code"
             for line in cell.source.splitlines() if not line.lstrip().startswith(("%", "!"))]
    return ast.parse("\n".join(lines), filename=path.name)


def _imported(tree: ast.Module) -> dict[str, object]:
    """Each name the notebook's imports bind, resolved (an error names what is missing)."""
    names: dict[str, object] = {}
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                module = importlib.import_module(alias.name)
                top = alias.name.split(".")[0]
                names[alias.asname or top] = (module if alias.asname
                                              else importlib.import_module(top))
        elif isinstance(node, ast.ImportFrom) and node.module:
            module = importlib.import_module(node.module)
            for alias in node.names:
                names[alias.asname or alias.name] = _member(module, alias.name)
    return names


def _member(module: ModuleType, name: str) -> object:
    if hasattr(module, name):
        return getattr(module, name)
    return importlib.import_module(f"{module.__name__}.{name}")  # a submodule


def _resolve(node: ast.expr, names: dict[str, object]) -> tuple[str, object] | None:
    """``(dotted name, object)`` of ``name.attr...`` from an imported name, else None."""
    if isinstance(node, ast.Name):
        return (node.id, names[node.id]) if node.id in names else None
    if isinstance(node, ast.Attribute):
        base = _resolve(node.value, names)
        if base is None:
            return None
        dotted, obj = base
        if not isinstance(obj, (ModuleType, type)):
            return None  # an instance's attributes are not checked statically
        assert hasattr(obj, node.attr), f"{dotted}.{node.attr} does not exist"
        return f"{dotted}.{node.attr}", getattr(obj, node.attr)
    return None


def _binds(call: ast.Call, dotted: str, target: object) -> None:
    """The call's positional count and keyword names fit ``target``'s signature."""
    starred = any(isinstance(a, ast.Starred) for a in call.args)
    if starred or any(k.arg is None for k in call.keywords) or not callable(target):
        return
    try:
        signature = inspect.signature(target)
    except (TypeError, ValueError):  # a builtin without a signature
        return
    try:
        signature.bind(*[None] * len(call.args), **{k.arg: None for k in call.keywords if k.arg})
    except TypeError as err:
        raise AssertionError(f"{dotted}(...) at line {call.lineno}: {err}") from err


@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.stem for p in NOTEBOOKS])
def test_every_name_and_call_the_notebook_takes_from_alte_resolves(path: Path) -> None:
    tree = _code(path)
    names = _imported(tree)
    assert any((isinstance(v, ModuleType) and v.__name__.startswith("alte"))
               or getattr(v, "__module__", "").startswith("alte") for v in names.values())
    for node in ast.walk(tree):
        if isinstance(node, ast.Attribute):
            _resolve(node, names)
        elif isinstance(node, ast.Call):
            found = _resolve(node.func, names)
            if found is not None and found[0].split(".")[0] in names:
                module = getattr(found[1], "__module__", "") or ""
                if module.startswith(("alte", "alte_elevation")):
                    _binds(node, *found)


def test_a_renamed_function_or_keyword_is_caught(tmp_path: Path) -> None:
    """Control: the check fails on the two faults it exists for."""
    nb = nbformat.v4.new_notebook()
    nb.cells = [nbformat.v4.new_code_cell("from alte.lab.studies import experiments\n"
                                          "experiments.terrain('sim_nav_1', 'data', 0, 12, "
                                          "progres=True)")]
    path = tmp_path / "bad_keyword.ipynb"
    nbformat.write(nb, str(path))
    with pytest.raises(AssertionError, match=r"experiments\.terrain.*progres"):
        test_every_name_and_call_the_notebook_takes_from_alte_resolves(path)
    nb.cells = [nbformat.v4.new_code_cell("from alte.lab.studies import experiments\n"
                                          "experiments.terrian('sim_nav_1')")]
    nbformat.write(nb, str(path))
    with pytest.raises(AssertionError, match=r"experiments\.terrian does not exist"):
        test_every_name_and_call_the_notebook_takes_from_alte_resolves(path)
    nb.cells = [nbformat.v4.new_code_cell("from alte.lab.studies.poses import benchmark, figure")]
    nbformat.write(nb, str(path))
    with pytest.raises(ModuleNotFoundError, match="figure"):
        test_every_name_and_call_the_notebook_takes_from_alte_resolves(path)
