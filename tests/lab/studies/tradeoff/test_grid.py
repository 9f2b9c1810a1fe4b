"""alte.lab.studies.tradeoff.grid: the report's trade-off grid, its tables and its ablations."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest
from support.tradeoff import Curve, synthetic_tradeoff

from alte.errors import ParameterError
from alte.lab.studies.analysis.tradeoff import prepare
from alte.lab.studies.sweep import BASE, parse_spec
from alte.lab.studies.thesis.claims import claim
from alte.lab.studies.tradeoff.grid import (
    OCCUPIED_SIZE,
    THESIS_ROWS,
    TRADEOFF_COLUMNS,
    Grid,
    ablations,
    front_order,
    run_grid,
    thesis_rows,
    tradeoff_table,
    write_grid,
)

_SPEC = {"terrains": ["sim_lan_1", "sim_lan_2", "sim_nav_1", "sim_nav_2"],
         "mappers": {m: {"rows": [{}]} for m in ("quadtree", "alte2d", "octomap", "alte3d")},
         "variants": {"shifted": {"set_b": "centers", "terrains": ["sim_lan_2", "sim_nav_1"]}}}


def _sweep_rows(table: pd.DataFrame) -> pd.DataFrame:
    """A synthetic trade-off table as ``alte sweep`` rows (params_json, run ids)."""
    rows = table.rename(columns={"params": "params_json"})
    return rows.assign(run_id=[f"r{i}" for i in range(len(rows))], frames_requested=20,
                       wall_s=1.0, frames=20, points=1000)


def _grid(variant: pd.DataFrame) -> Grid:
    """Base rows of the default curves plus ``variant`` rows named ``shifted``."""
    base = synthetic_tradeoff().assign(variant=BASE)
    both = pd.concat([base, variant.assign(variant="shifted")], ignore_index=True)
    table = tradeoff_table(_sweep_rows(both))
    spec = parse_spec(_SPEC, "grid.yaml")
    return Grid(spec, table[table["variant"] == BASE].drop(columns="variant"), table,
                runs=len(table), ran=len(table), seconds=1.0)


def test_tradeoff_table_schema():
    table = tradeoff_table(_sweep_rows(synthetic_tradeoff()))
    present = [c for c in TRADEOFF_COLUMNS if c in table.columns]
    assert set(TRADEOFF_COLUMNS) - set(present) == {"hd_minus_mhd_m"}  # not in the synthetic
    assert list(table.columns[:len(present)]) == present
    assert list(table.columns[:5]) == ["terrain", "case", "mapper", "params", "seed"]
    assert not {"run_id", "params_json", "wall_s"} & set(table.columns)
    assert set(table["case"]) == {"lan", "nav"}
    json.loads(table["params"].iloc[0])
    with pytest.raises(ParameterError, match="no finished runs"):
        tradeoff_table(_sweep_rows(synthetic_tradeoff()).iloc[:0])


def test_thesis_rows_keep_the_thesis_settings_only():
    table = prepare(synthetic_tradeoff(seeds=(0,)))
    kept = thesis_rows(table)
    assert set(kept["mapper"]) == {"quadtree", "alte2d", "octomap", "alte3d"}
    quadtree = kept[kept["mapper"] == "quadtree"]
    assert set(quadtree["p_max_points"]) == {25, 100, 150, 200, 500, 1000} & set(
        table["p_max_points"].dropna())
    assert set(kept[kept["mapper"] == "octomap"]["p_resolution"]) == {1.0, 2.0, 3.0, 4.0,
                                                                       5.0, 6.0}


def test_ablations_name_what_moves_a_verdict():
    # under the variant 2D-ALTE's curve is four times better: a claim it is better moves
    better = synthetic_tradeoff({"alte2d": Curve(scale=0.25)},
                                terrains={m: ("sim_lan_2",) if m in ("quadtree", "alte2d")
                                          else ("sim_nav_1",) for m in
                                          ("quadtree", "alte2d", "octomap", "alte3d")},
                                rng_seed=1)
    grid = _grid(better)
    chosen = [claim("6-quadtree-worse"), claim("5.1.1-octomap-size")]
    verdicts, cells = ablations(grid, chosen)
    assert list(verdicts.columns[:3]) == ["id", "section", "claim"]
    assert {BASE, OCCUPIED_SIZE, THESIS_ROWS, "shifted", "moves"} <= set(verdicts.columns)
    row = verdicts.set_index("id").loc["6-quadtree-worse"]
    assert not row[BASE].startswith("holds") and row["shifted"].startswith("holds")
    assert "shifted" in row["moves"]
    # Octomap's free leaves (70 % of its cells here) decide its size claim
    size = verdicts.set_index("id").loc["5.1.1-octomap-size"]
    assert size[BASE] != size[OCCUPIED_SIZE] and OCCUPIED_SIZE in size["moves"]
    assert set(cells["variant"]) >= {BASE, "shifted"}
    assert set(cells["terrain"]) <= {"sim_lan_2", "sim_nav_1"}
    assert grid.variant_texts[OCCUPIED_SIZE].startswith("map size counted as occupied")


def test_ablations_need_variants():
    table = tradeoff_table(_sweep_rows(synthetic_tradeoff().assign(variant=BASE)))
    spec = parse_spec({k: v for k, v in _SPEC.items() if k != "variants"})
    with pytest.raises(ParameterError, match="no ablation variants"):
        ablations(Grid(spec, table, table, 1, 1, 1.0), [claim("6-quadtree-worse")])


def test_write_grid(tmp_path):
    grid = _grid(synthetic_tradeoff(terrains={m: ("sim_lan_2",) if m in ("quadtree", "alte2d")
                                              else ("sim_nav_1",) for m in
                                              ("quadtree", "alte2d", "octomap", "alte3d")}))
    written = write_grid(grid, tmp_path, claims=[claim("6-quadtree-worse")])
    assert [p.name for p in written.paths] == ["tradeoff.csv", "tradeoff_variants.csv",
                                               "ablation.csv", "ablation_cells.csv"]
    back = pd.read_csv(tmp_path / "tradeoff.csv")
    assert len(back) == len(grid.table) and "variant" not in back
    assert list(written.ablation["id"]) == ["6-quadtree-worse"]


def test_run_grid_end_to_end(tmp_path):
    """A tiny spec through the sweep engine: the trade-off table has its schema and seeds."""
    spec = tmp_path / "tiny.yaml"
    spec.write_text("terrains: [sim_lan_1]\nframes: 3\nseeds: [0, 1]\n"
                    "truth: {n_samples: 500, grid_step: 0.5}\n"
                    "mappers:\n  quadtree: {grid: {max_points: [50, 400]}}\n"
                    "  alte2d: {grid: {kappa: [0.1], max_res: [3, 4]}}\n"
                    "variants:\n  occupied: {set_b: occupied}\n")
    grid = run_grid(spec, scheduler="serial", data_dir=str(tmp_path / "data"),
                    output=tmp_path / "runs", progress=False, frames=2, seeds=[3, 4])
    assert grid.spec.frames == 2 and grid.spec.seeds == (3, 4) and not grid.failed
    assert grid.cpu_s > 0 and grid.seconds > 0
    assert grid.runs == grid.ran == 8 + 8  # set B changes both 2D mappers' runs
    assert len(grid.table) == 8 and set(grid.table["seed"]) == {3, 4}
    assert set(TRADEOFF_COLUMNS) - {"accuracy_mean_m"} <= set(grid.table.columns)
    assert grid.table["frames"].eq(2).all() and np.isfinite(grid.table["mhd_m"]).all()
    assert grid.variants.groupby("variant").size().to_dict() == {BASE: 8, "occupied": 8}
    again = run_grid(spec, scheduler="serial", data_dir=str(tmp_path / "data"),
                     output=tmp_path / "runs", progress=False, frames=2, seeds=[3, 4])
    assert again.ran == 0 and again.runs == 16


def test_front_order_compares_who_leads_at_equal_size():
    where = {m: ("sim_lan_2",) if m in ("quadtree", "alte2d") else ("sim_nav_1",)
             for m in ("quadtree", "alte2d", "octomap", "alte3d")}
    short = synthetic_tradeoff({"alte2d": Curve(scale=0.5), "alte3d": Curve(scale=0.5)},
                               terrains=where)
    whole = synthetic_tradeoff({"alte2d": Curve(scale=0.5), "alte3d": Curve(scale=2.0)},
                               terrains=where, seeds=(0,), rng_seed=3)
    order = front_order(short, whole)
    assert set(order["terrain"]) == {"sim_lan_2", "sim_nav_1"}
    lan = order[(order["terrain"] == "sim_lan_2") & (order["metric"] == "mhd_m")]
    assert list(lan["level"]) == [1000.0, 5000.0, 20000.0]
    assert (lan["lead_short"] == "alte2d").all() and lan["same"].all()
    nav = order[(order["terrain"] == "sim_nav_1") & (order["metric"] == "mhd_m")]
    assert (nav["lead_whole"] == "octomap").all() and not nav["same"].any()
    assert {"alte2d_short", "quadtree_whole", "octomap_whole"} <= set(order.columns)
