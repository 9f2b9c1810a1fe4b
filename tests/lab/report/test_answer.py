"""The front page's bottom line is read from the run's tables: change one, the text changes."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import pandas as pd
import pytest
from support.tradeoff import Curve, synthetic_tradeoff

from alte.lab.report.answer import answer_view
from alte.lab.report.html import run_index_html
from alte.lab.studies.analysis.tables import write_csv

from .conftest import make_front_run


@pytest.fixture(scope="module")
def built(tmp_path_factory: pytest.TempPathFactory) -> tuple[dict, Path]:
    """One finished run (its record and folder), built once for the module: each test
    changes a copy of it (:func:`_front_run`), so the claims and figures are made once."""
    run_dir = tmp_path_factory.mktemp("front") / "run"
    return make_front_run(run_dir), run_dir


def _front_run(built: tuple[dict, Path], run_dir: Path) -> dict:
    """A copy of the built run at ``run_dir`` (as ``make_front_run`` writes it); its record."""
    record, template = built
    shutil.copytree(template, run_dir)
    return record


def _answer(record: dict, run_dir: Path) -> str:
    page = run_index_html(record, run_dir, sorted((run_dir / "tables").glob("*.csv")))
    section = page[page.index('id="answer"'):page.index('id="claims"')]
    return re.sub(r"\s+", " ", re.sub(r"<[^>]+>", " ", section))


def test_the_answer_follows_the_trade_off_table(built, tmp_path: Path) -> None:
    before = _answer(*built)
    assert "ranked by height RMSE: 2D-ALTE under" in before
    assert "Quadtree under none" in before and "3D-ALTE under" in before
    # the same run with Quadtree's maps made four times better: the choice turns
    table = synthetic_tradeoff({"alte2d": Curve(scale=0.5), "alte3d": Curve(scale=0.5),
                                "quadtree": Curve(scale=0.125)})
    run = tmp_path / "b"
    _front_run(built, run)
    write_csv(table, run / "tables", "tradeoff", overwrite=True)
    view = answer_view(run / "tables")
    landing = view.uses[0]
    assert landing.summary.startswith("For landing, ranked by height RMSE: Quadtree under")
    assert {row.mapper for row in landing.rows} == {"quadtree"}
    assert landing.rows[0].choose.startswith("Quadtree max_points=")
    assert "2D-ALTE at best:" in landing.rows[0].rival


def test_without_a_grid_there_is_no_answer_and_the_page_says_so(built, tmp_path: Path) -> None:
    run = tmp_path / "run"
    record = _front_run(built, run)
    (run / "tables" / "tradeoff.csv").unlink()
    assert answer_view(run / "tables") is None
    page = run_index_html(record, run, sorted((run / "tables").glob("*.csv")))
    assert "This run has no trade-off grid" in page


def test_real_fronts_add_the_agreement_of_the_real_sequence(built, tmp_path: Path) -> None:
    run = tmp_path / "run"
    _front_run(built, run)
    real = synthetic_tradeoff({"alte2d": Curve(scale=2.0)}, seeds=(0,), terrains={
        m: ("balm_seq",) for m in ("quadtree", "alte2d", "octomap", "alte3d")})
    write_csv(real.assign(frames=20, reference_points=1000), run / "tables",
              "realdata_fronts")
    view = answer_view(run / "tables")
    lines = " ".join(view.uses[0].real)
    assert "MHD at equal size: simulated terrains 2D-ALTE on" in lines
    assert "balm_seq Quadtree on 3 of 3 reads" in lines and "disagrees" in lines
    assert "Real data: balm_seq, 20 real scans" in view.real_note


def test_real_terrain_classes_show_where_the_built_in_answer_holds(built, tmp_path: Path) -> None:
    run = tmp_path / "run"
    record = _front_run(built, run)
    sites = {"quadtree": ("ign_farmland",), "alte2d": ("ign_farmland",),
             "octomap": ("bcts_slope",), "alte3d": ("bcts_slope",)}
    real = synthetic_tradeoff({"alte2d": Curve(scale=0.5)}, terrains=sites).assign(
        evidence="flown", terrain_class=lambda t: t["terrain"].map(
            {"ign_farmland": "flat open", "bcts_slope": "slope"}))
    write_csv(real, run / "tables", "realterrain_fronts")
    view = answer_view(run / "tables")
    landing, navigation = view.uses
    assert [(r.terrain_class, r.terrains, r.verdict) for r in landing.classes] == [
        ("flat open", "ign_farmland", "holds")]
    assert navigation.classes[0].terrain_class == "slope"
    page = run_index_html(record, run, sorted((run / "tables").glob("*.csv")))
    assert "On real terrain, by class" in page and "<td>flat open</td>" in page


def test_a_plugin_in_the_grid_is_read_against_the_thesis_two(built, tmp_path: Path) -> None:
    """A 2D mapper beyond the thesis' two (a plugin, ``dims`` 2) with a height variance:
    the page says where it beats or loses and how often its sigma covers the truth."""
    run = tmp_path / "run"
    record = _front_run(built, run)
    table = synthetic_tradeoff()
    extra = table[table["mapper"] == "quadtree"].assign(mapper="heightgrid", within_2sigma=0.9,
                                                        sigma_mean_m=0.012)
    extra["height_rmse_m"] *= 0.5
    table = pd.concat([table, extra], ignore_index=True)
    table["dims"] = table["mapper"].map({"octomap": 3, "alte3d": 3}).fillna(2).astype(int)
    write_csv(table, run / "tables", "tradeoff", overwrite=True)
    page = run_index_html(record, run, sorted((run / "tables").glob("*.csv")))
    text = re.sub(r"\s+", " ", re.sub(r"<[^>]+>", " ", page))
    assert "Beyond the thesis' two" in text
    assert re.search(r"heightgrid against Quadtree, height RMSE at equal size: leads on sim_lan_1 "
                     r"\(3 of 3 reads\)", text)
    assert re.search(r"Claimed height uncertainty .* heightgrid on the simulated terrains "
                     r"\(sim_lan_1, sim_lan_2\): the true height lies within 2 claimed sigma "
                     r"on 90\.0 %", text)
