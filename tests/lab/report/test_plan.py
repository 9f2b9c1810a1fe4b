"""Plan building and notebook parameter validation (no kernels started)."""

from __future__ import annotations

from pathlib import Path

import pytest

from alte.errors import ParameterError, ReportError
from alte.lab.report.plan import (
    PLAN,
    QUICK_FRAMES,
    SENSOR_SEEDS,
    SENSOR_SEEDS_ALL,
    TERRAINS,
    Entry,
    build_plan,
    load_plan,
    notebook_parameters,
    parse_param,
)
from alte.paths import REPO_ROOT

from .conftest import make_notebook, write_plan

ROOT = REPO_ROOT
ENTRIES = (Entry("good", "good.ipynb", {"ROWS": 1}, {"ROWS": 5}),
           Entry("bad", "bad.ipynb", None, {}),
           Entry("slow", "slow.ipynb", {}, None, terrains=("sim_nav_1",)))


@pytest.mark.parametrize(("text", "expected"), [
    ("ROWS=3", ("ROWS", 3)), ("FRAMES=None", ("FRAMES", None)),
    ("TERRAIN=sim_nav_1", ("TERRAIN", "sim_nav_1")), ("X='a=b'", ("X", "a=b")),
    ("SIZES=[1, 2]", ("SIZES", [1, 2])), ("NAME=", ("NAME", "")),
])
def test_parse_param(text: str, expected: tuple) -> None:
    assert parse_param(text) == expected


@pytest.mark.parametrize("text", ["ROWS", "=3", "1X=2", "A B=1"])
def test_parse_param_rejects_malformed(text: str) -> None:
    with pytest.raises(ParameterError, match="expected NAME=VALUE"):
        parse_param(text)


def test_notebook_parameters_reads_defaults(notebooks: Path) -> None:
    assert notebook_parameters(notebooks / "good.ipynb") == {
        "OUT_DIR": "reports/scratch/good", "TABLES_DIR": "reports/scratch/tables",
        "SEED": 0, "ROWS": 3}


def test_notebook_parameters_missing_file(tmp_path: Path) -> None:
    with pytest.raises(ReportError, match=r"nope\.ipynb does not exist"):
        notebook_parameters(tmp_path / "nope.ipynb")


def test_notebook_parameters_corrupt_file(tmp_path: Path) -> None:
    (tmp_path / "broken.ipynb").write_text("{not json")
    with pytest.raises(ReportError, match=r"broken\.ipynb: cannot read its parameters"):
        notebook_parameters(tmp_path / "broken.ipynb")


def test_modes_select_entries(notebooks: Path) -> None:
    quick = build_plan(ENTRIES, quick=True, notebooks_dir=notebooks)
    full = build_plan(ENTRIES, quick=False, notebooks_dir=notebooks)
    assert [r.name for r in quick] == ["good", "slow"]
    assert [r.name for r in full] == ["good", "bad"]
    assert quick[0].parameters == {"ROWS": 1} and full[0].parameters == {"ROWS": 5}
    assert quick[0].value("SEED") == 0 and quick[0].value("ROWS") == 1
    assert quick[1].terrains == ("sim_nav_1",) and quick[0].terrains == ()


def test_only_selects_by_run_or_notebook(notebooks: Path) -> None:
    runs = build_plan(ENTRIES, quick=False, notebooks_dir=notebooks, only=["bad"])
    assert [r.name for r in runs] == ["bad"]
    with pytest.raises(ParameterError, match=r"run badd: no such run; valid: bad, good"):
        build_plan(ENTRIES, quick=False, notebooks_dir=notebooks, only=["badd"])


def test_overrides_go_to_notebooks_declaring_them(notebooks: Path) -> None:
    runs = build_plan(ENTRIES, quick=False, notebooks_dir=notebooks,
                      overrides={"ROWS": 7, "MESSAGE": "x"})
    assert runs[0].parameters == {"ROWS": 7}
    assert runs[1].parameters == {"MESSAGE": "x"}


def test_misspelt_parameter_lists_valid_ones(notebooks: Path) -> None:
    with pytest.raises(ParameterError,
                       match=r"unknown notebook parameter ROWSS; valid parameters: "
                             r"MESSAGE, ROWS, SEED$"):
        build_plan(ENTRIES, quick=False, notebooks_dir=notebooks, overrides={"ROWSS": 1})


def test_runner_parameters_cannot_be_overridden(notebooks: Path) -> None:
    with pytest.raises(ParameterError, match="OUT_DIR: set by the runner"):
        build_plan(ENTRIES, quick=False, notebooks_dir=notebooks, overrides={"OUT_DIR": "x"})


def test_plan_parameter_must_be_declared(notebooks: Path) -> None:
    entries = (Entry("good", "good.ipynb", {"FRAMESS": 3}),)
    with pytest.raises(ParameterError, match=r"plan entry good: good\.ipynb has no parameter "
                                             r"FRAMESS; valid parameters: OUT_DIR, ROWS"):
        build_plan(entries, quick=True, notebooks_dir=notebooks)


def test_notebook_without_out_dir(tmp_path: Path) -> None:
    make_notebook(tmp_path / "x.ipynb", "A = 1\n", "print(A)")
    with pytest.raises(ReportError, match=r"x\.ipynb declares no OUT_DIR"):
        build_plan((Entry("x", "x.ipynb"),), quick=True, notebooks_dir=tmp_path)


def test_terrain_comes_from_parameter_default(tmp_path: Path) -> None:
    make_notebook(tmp_path / "t.ipynb", 'OUT_DIR = "o"\nTERRAIN = "sim_lan_2"\n', "pass")
    runs = build_plan((Entry("t", "t.ipynb", {}, {"TERRAIN": "exp_nav_1"}),), quick=True,
                      notebooks_dir=tmp_path)
    assert runs[0].terrains == ("sim_lan_2",)
    runs = build_plan((Entry("t", "t.ipynb", {}, {"TERRAIN": "exp_nav_1"}),), quick=False,
                      notebooks_dir=tmp_path)
    assert runs[0].terrains == ("exp_nav_1",)


def test_load_plan_round_trip(tmp_path: Path) -> None:
    path = write_plan(tmp_path / "plan.json", [
        {"name": "a", "notebook": "a.ipynb", "quick": None, "full": {"X": 1},
         "terrains": ["sim_nav_1"]}])
    assert load_plan(path) == (Entry("a", "a.ipynb", None, {"X": 1}, ("sim_nav_1",)),)


@pytest.mark.parametrize(("text", "why"), [
    ("[{", "Expecting property name"),
    ('{"name": "a"}', "expected a list of entries"),
    ('[{"name": "a"}]', r"plan entry: notebook='' out of range \(an \.ipynb file name\)"),
    ('[{"name": "a", "notebook": "a.ipynb", "x": 1}]', r"plan entry: unknown parameter\(s\) x"),
    ('[{"name": "a", "notebook": "a.ipynb", "terrains": 3}]', "terrains=3 is not a list"),
])
def test_load_plan_rejects_bad_files(tmp_path: Path, text: str, why: str) -> None:
    (tmp_path / "plan.json").write_text(text)
    with pytest.raises(ReportError, match=rf"plan .*plan\.json: .*{why}"):
        load_plan(tmp_path / "plan.json")


def test_builtin_plan_shape() -> None:
    names = [e.name for e in PLAN]
    assert len(names) == len(set(names))
    ch4 = [e for e in PLAN if e.notebook == "ch4_terrain.ipynb"]
    assert [e.full["TERRAIN"] for e in ch4] == list(TERRAINS)
    assert 0 < sum(e.quick is not None for e in ch4) < len(TERRAINS)
    assert all(e.full.get("FRAMES", None) is None for e in PLAN)
    assert {e.quick["FRAMES"] for e in PLAN if e.quick is not None} == {QUICK_FRAMES}
    assert {e.notebook for e in PLAN} >= {"ch2_test_benchmark.ipynb", "ch5_analysis.ipynb"}
    # chapter 5, the longest, starts first when notebooks run side by side
    assert [e.name for e in PLAN if e.first] == ["ch5_analysis"]


def test_the_sensor_studys_seeds_full_and_in_the_report() -> None:
    """``make report`` runs the sensor study on SENSOR_SEEDS, ``make report-full`` on
    every seed of SENSOR_SEEDS_ALL (the Makefile's literal is the plan's)."""
    (ch5,) = [e for e in PLAN if e.name == "ch5_analysis"]
    assert ch5.full is not None and ch5.full["SENSOR_SEEDS"] == list(SENSOR_SEEDS)
    assert set(SENSOR_SEEDS) < set(SENSOR_SEEDS_ALL)
    makefile = (ROOT / "Makefile").read_text()
    assert f'--param "SENSOR_SEEDS={list(SENSOR_SEEDS_ALL)}"' in makefile


def test_terrains_match_the_simulator() -> None:
    from alte.sim import TERRAINS as SIMULATED

    assert set(TERRAINS) == set(SIMULATED)


@pytest.mark.parametrize("quick", [True, False])
def test_builtin_plan_matches_real_notebooks(quick: bool) -> None:
    folder = ROOT / "notebooks"
    missing = [e.notebook for e in PLAN if not (folder / e.notebook).exists()]
    if missing:
        pytest.skip(f"notebooks absent: {', '.join(sorted(set(missing)))}")
    runs = build_plan(PLAN, quick=quick, notebooks_dir=folder)
    assert runs and all(r.notebook.exists() for r in runs)
    if quick:  # one simulation per terrain serves every notebook using it
        assert {r.value("FRAMES") for r in runs} == {QUICK_FRAMES}
