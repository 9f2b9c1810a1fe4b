"""Every notebook is parameterisable by papermill and stored clean; nbval runs headless.

The notebooks themselves are executed by ``pytest --nbval-lax notebooks/`` (``make
test`` executes ``ch4_terrain``, ``make check-full`` every chapter; test_calls.py reads
every notebook's calls in ``make test``); these tests check what that run and ``alte
report`` rely on.
"""

from __future__ import annotations

import ast
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import nbformat
import papermill
import pytest
from papermill.iorw import load_notebook_node
from papermill.parameterize import parameterize_notebook
from alte.paths import REPO_ROOT

ROOT = REPO_ROOT
NOTEBOOKS = sorted((ROOT / "notebooks").glob("*.ipynb"))
CASES = [pytest.param(p, id=p.stem) for p in NOTEBOOKS] or [
    pytest.param(None, marks=pytest.mark.skip(reason="no notebooks/*.ipynb yet"))]


def _read(path: Path) -> nbformat.NotebookNode:
    return nbformat.read(str(path), as_version=4)


def _tagged(nb: nbformat.NotebookNode, tag: str) -> list[int]:
    return [i for i, c in enumerate(nb.cells) if tag in c.get("metadata", {}).get("tags", [])]


@pytest.mark.parametrize("path", CASES)
def test_one_parameters_cell_with_upper_case_names(path: Path) -> None:
    nb = _read(path)
    cells = _tagged(nb, "parameters")
    assert len(cells) == 1, f"{path.name}: {len(cells)} cells tagged 'parameters'"
    assert nb.cells[cells[0]].cell_type == "code"
    names = list(papermill.inspect_notebook(str(path)))
    assert names, f"{path.name}: the parameters cell declares nothing"
    assert all(n.isupper() and n.isidentifier() for n in names), names


@pytest.mark.parametrize("path", CASES)
def test_papermill_sees_every_assignment(path: Path) -> None:
    """Each name the parameters cell assigns is a parameter papermill can report and inject."""
    nb = _read(path)
    tree = ast.parse(nb.cells[_tagged(nb, "parameters")[0]].source)
    assigned = [t.id for node in tree.body if isinstance(node, ast.Assign | ast.AnnAssign)
                for t in (node.targets if isinstance(node, ast.Assign) else [node.target])
                if isinstance(t, ast.Name)]
    missed = sorted(set(assigned) - set(papermill.inspect_notebook(str(path))))
    assert not missed, f"{path.name}: papermill cannot parse the lines assigning {missed}"


@pytest.mark.parametrize("path", CASES)
def test_papermill_injects_every_parameter(path: Path) -> None:
    declared = papermill.inspect_notebook(str(path))
    values = {name: f"injected-{name}" for name in declared}
    nb = parameterize_notebook(load_notebook_node(str(path)), values, kernel_name="python3",
                               language="python")
    injected = _tagged(nb, "injected-parameters")
    assert len(injected) == 1
    assert injected[0] == _tagged(nb, "parameters")[0] + 1
    tree = ast.parse(nb.cells[injected[0]].source)
    assigned = {t.id: ast.literal_eval(node.value) for node in tree.body
                if isinstance(node, ast.Assign) for t in node.targets}
    assert assigned == values


@pytest.mark.parametrize("path", CASES)
def test_out_dir_default_is_scratch(path: Path) -> None:
    declared = papermill.inspect_notebook(str(path))
    assert "OUT_DIR" in declared, f"{path.name}: no OUT_DIR parameter"
    assert ast.literal_eval(declared["OUT_DIR"]["default"]) == f"reports/scratch/{path.stem}"


@pytest.mark.parametrize("path", CASES)
def test_outputs_stripped(path: Path) -> None:
    nb = _read(path)
    dirty = [i for i, c in enumerate(nb.cells) if c.cell_type == "code"
             and (c.get("outputs") or c.get("execution_count") is not None)]
    assert not dirty, f"{path.name}: cells {dirty} hold outputs or execution counts"
    assert nb.metadata.get("kernelspec", {}).get("name") == "python3"


@pytest.mark.parametrize("path", CASES)
def test_stored_valid_with_an_id_per_cell(path: Path) -> None:
    """nbformat 4.5 wants a unique id per cell; without one every run of the notebook
    (``make report``, nbval) warns about it."""
    raw = json.loads(path.read_text())
    ids = [c.get("id") for c in raw["cells"]]
    assert None not in ids and len(set(ids)) == len(ids), f"{path.name}: cell ids {ids}"
    nbformat.validate(nbformat.reads(path.read_text(), as_version=4))


@pytest.mark.parametrize("path", CASES)
def test_last_code_cell_saves_results(path: Path) -> None:
    code = [c for c in _read(path).cells if c.cell_type == "code"]
    assert "save_results(" in code[-1].source, f"{path.name}: last code cell"


def _tiny_notebook(path: Path, root: Path) -> None:
    nb = nbformat.v4.new_notebook()
    nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3",
                                 "language": "python"}
    params = nbformat.v4.new_code_cell('OUT_DIR = "reports/scratch/tiny"')
    params.metadata["tags"] = ["parameters"]
    check = nbformat.v4.new_code_cell(
        "import os, matplotlib, pyvista\n"
        "assert matplotlib.get_backend().lower() == 'agg', matplotlib.get_backend()\n"
        "assert pyvista.OFF_SCREEN\n"
        "assert os.environ['ALTE_RENDER'] == 'static'\n"
        f"assert os.getcwd() == {str(root)!r}, os.getcwd()\n"
        "from alte.lab.notebook import setup\n"
        "print(setup())")
    nb.cells = [params, check]
    nbformat.write(nb, str(path))


@pytest.mark.full
@pytest.mark.slow
def test_nbval_runs_headless_from_repo_root(tmp_path: Path) -> None:
    """notebooks/conftest.py makes nbval kernels headless and start in its parent folder."""
    folder = tmp_path / "notebooks"
    folder.mkdir()
    shutil.copy(ROOT / "notebooks" / "conftest.py", folder / "conftest.py")
    _tiny_notebook(folder / "tiny.ipynb", tmp_path)
    env = {k: v for k, v in os.environ.items()
           if k not in {"MPLBACKEND", "PYVISTA_OFF_SCREEN", "ALTE_RENDER", "DISPLAY"}}
    command = [sys.executable, "-m", "pytest", "--nbval-lax", "-q", "-p", "no:cacheprovider",
               "-p", "no:dash", "--rootdir", str(tmp_path), str(folder / "tiny.ipynb")]
    proc = subprocess.run(command, cwd=tmp_path, env=env, capture_output=True, text=True,
                          timeout=300, check=False)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "2 passed" in proc.stdout
    (folder / "conftest.py").unlink()  # control: without it the checks fail
    proc = subprocess.run(command, cwd=tmp_path, env=env, capture_output=True, text=True,
                          timeout=300, check=False)
    assert proc.returncode != 0
    assert "1 failed" in proc.stdout
