"""Whole-mission evidence: written by ``alte sweep --evidence`` from a real (small) grid,
read back with its provenance, and its verdicts compared with a short-mission claims table;
the chapter 5 hook writes ``claims_missions.csv`` only when evidence is committed."""

from __future__ import annotations

import json
from pathlib import Path

import pandas as pd
import pytest

from alte.cli import main
from alte.errors import ReportError
from alte.lab.studies.missions import (
    CELLS,
    EVIDENCE_TABLES,
    PROVENANCE,
    WHOLE_MISSIONS,
    compare_verdicts,
    load_mission_evidence,
    outcome_summary,
    write_comparison,
)
from alte.lab.studies.thesis.claims import CLAIMS

SPEC = """\
name: tiny
terrains: [sim_lan_2, sim_nav_1]
frames: 6
seeds: [0, 1]
data_dir: {data}
output: {out}
truth: {{n_samples: 3000, grid_step: 0.5}}
mappers:
  quadtree:
    grid: {{max_points: [20, 100, 400]}}
  alte2d:
    grid: {{kappa: [0.01, 1.0], max_res: [4, 6], min_pts: [10]}}
  octomap:
    grid: {{resolution: [1.0, 2.0, 4.0]}}
  alte3d:
    grid: {{max_res: [4, 6], min_pts_split: [10], min_pts: [5, 20]}}
"""


@pytest.fixture(scope="module")
def evidence(tmp_path_factory) -> Path:
    """The evidence folder of a 2-terrain, 2-seed, 6-scan grid, made by the CLI."""
    root = tmp_path_factory.mktemp("missions")
    spec = root / "tiny.yaml"
    spec.write_text(SPEC.format(data=root / "data", out=root / "runs"))
    folder = root / "evidence"
    assert main(["sweep", str(spec), "--scheduler", "serial", "--no-progress",
                 "--evidence", str(folder)]) == 0
    return folder


def test_sweep_writes_the_evidence_folder_with_its_provenance(evidence: Path) -> None:
    assert sorted(p.name for p in evidence.iterdir()) == sorted(
        [f"{n}.csv" for n in (*EVIDENCE_TABLES, CELLS)] + [PROVENANCE])
    found = load_mission_evidence(evidence)
    made = found.provenance
    assert made.command.startswith("alte sweep ") and f"--evidence {evidence}" in made.command
    assert made.runs == made.ran == 2 * 2 * (3 + 4 + 3 + 4) and made.seeds == [0, 1]
    assert made.frames == 6 and made.cpu_s > 0 and made.wall_s > 0
    assert made.commit == "unknown" or len(made.commit.removesuffix("-dirty")) == 40
    assert list(found.claims["id"]) == [c.id for c in CLAIMS]
    assert set(found.claims["verdict"]) <= {"holds", "does not hold", "depends",
                                            "not measurable", "no data"}
    assert {"mhd_m", "height_rmse_m", "completeness"} <= set(found.fronts["metric"])
    assert set(found.fronts["mapper"]) == {"quadtree", "alte2d", "octomap", "alte3d"}
    assert not found.equal_size.empty and not found.equal_fidelity.empty
    assert set(found.cells["id"]) <= set(found.claims["id"]) and len(found.cells) > 0
    # each front point is one map: no two points of a front share a size with one better
    for _, front in found.fronts.groupby(["terrain", "mapper", "seed", "metric"]):
        assert front["basis_functions"].is_unique


def test_verdicts_side_by_side_marked_where_they_differ(evidence: Path, tmp_path) -> None:
    whole = load_mission_evidence(evidence).claims
    short = whole.copy()
    flip = short.index[:2]
    short.loc[flip, "verdict"] = ["absent-on-purpose", "holds"]
    short = short.drop(index=short.index[-1])  # a claim only the whole missions have
    table = write_comparison(short, evidence, tmp_path)
    assert (tmp_path / "claims_missions.csv").is_file()
    assert table["id"].tolist() == [*short["id"].tolist(), whole["id"].iloc[-1]]
    differs = set(table.loc[table["differs"], "id"])
    expected = {whole["id"][0], whole["id"].iloc[-1]}
    if whole["verdict"][1] != "holds":
        expected.add(whole["id"][1])
    assert differs == expected
    last = table.iloc[-1]
    assert last["verdict_20_scans"] == "absent" and last["claim"] == whole["claim"].iloc[-1]
    read = pd.read_csv(tmp_path / "claims_missions.csv", keep_default_na=False)
    assert read["differs"].astype(str).tolist() == table["differs"].astype(str).tolist()


def test_no_evidence_committed_means_no_comparison(tmp_path) -> None:
    short = pd.DataFrame({"id": ["a"], "section": ["5"], "claim": ["c"], "verdict": ["holds"],
                          "depends_on": [""]})
    assert write_comparison(short, tmp_path / "absent", tmp_path).empty
    assert write_comparison(short, None, tmp_path).empty
    assert not (tmp_path / "claims_missions.csv").exists()


def test_compare_verdicts_joins_on_the_claim_id() -> None:
    short = pd.DataFrame({"id": ["a", "b"], "section": ["5.1", "5.2"], "claim": ["A", "B"],
                          "verdict": ["holds", "depends"], "depends_on": ["", "terrain"]})
    whole = pd.DataFrame({"id": ["b", "a"], "section": ["5.2", "5.1"], "claim": ["B", "A"],
                          "verdict": ["depends", "does not hold"], "depends_on": ["size", ""]})
    table = compare_verdicts(short, whole)
    assert table[["id", "verdict_20_scans", "verdict_whole_missions", "differs"]].values.tolist(
    ) == [["a", "holds", "does not hold", True], ["b", "depends", "depends", False]]
    assert table["depends_on_whole_missions"].tolist() == ["", "size"]


def test_incomplete_evidence_is_named(evidence: Path, tmp_path) -> None:
    with pytest.raises(ReportError, match=r"missing claims.csv, equal_size.csv, .*"
                                          r"provenance.json \(made by a sweep given an evidence "
                                          r"folder\)"):
        load_mission_evidence(tmp_path)
    copy = tmp_path / "copy"
    copy.mkdir()
    for path in evidence.iterdir():
        (copy / path.name).write_bytes(path.read_bytes())
    (copy / PROVENANCE).write_text(json.dumps({"command": "x"}))
    with pytest.raises(ReportError, match=r"provenance.json: unreadable"):
        load_mission_evidence(copy)


def _cells(rows: list[tuple[str, str, str]]) -> pd.DataFrame:
    return pd.DataFrame(rows, columns=["id", "terrain", "outcome"])


def test_outcomes_are_counted_per_terrain() -> None:
    cells = _cells([("a", "sim_nav_1", "does not hold"), ("a", "sim_lan_1", "holds"),
                    ("a", "sim_lan_1", "inconclusive"), ("a", "sim_lan_1", "holds"),
                    ("a", "sim_nav_1", "equal")])
    assert outcome_summary(cells) == ("sim_lan_1: 2 hold, 1 undecided; "
                                      "sim_nav_1: 1 do not hold, 1 equal")
    assert outcome_summary(cells.iloc[:0]) == ""


def test_a_differing_claim_says_what_moved_on_each_side() -> None:
    short = pd.DataFrame({"id": ["a", "b"], "section": ["5.1", "5.2"], "claim": ["A", "B"],
                          "verdict": ["holds", "depends"], "depends_on": ["", "terrain"]})
    whole = short.assign(verdict=["does not hold", "depends"])
    short_cells = _cells([("a", "sim_lan_1", "holds"), ("b", "sim_lan_1", "holds")])
    whole_cells = _cells([("a", "sim_lan_1", "does not hold"), ("a", "sim_lan_1", "holds"),
                          ("b", "sim_lan_2", "holds")])
    table = compare_verdicts(short, whole, short_cells, whole_cells)
    assert table["why"].tolist() == [
        "20 scans: sim_lan_1: 1 hold | whole missions: sim_lan_1: 1 hold, 1 do not hold", ""]
    assert compare_verdicts(short, whole)["why"].tolist() == ["", ""]


def test_the_comparison_reads_the_reports_own_cells(evidence: Path, tmp_path) -> None:
    found = load_mission_evidence(evidence)
    short = found.claims.assign(verdict="holds")
    own = found.cells.assign(outcome="holds")
    own.to_csv(tmp_path / f"{CELLS}.csv", index=False)
    table = write_comparison(short, evidence, tmp_path)
    moved = table[table["differs"]]
    assert len(moved) > 0
    for claim_id, why in zip(moved["id"], moved["why"], strict=True):
        if (found.cells["id"] == claim_id).any():
            assert why.startswith("20 scans: ") and " | whole missions: " in why


def test_the_committed_whole_mission_evidence_covers_the_catalogue() -> None:
    folder = Path(__file__).resolve().parents[3] / WHOLE_MISSIONS
    found = load_mission_evidence(folder)
    made = found.provenance
    assert made.spec == "notebooks/sweeps/tradeoff-full.yaml" and made.frames is None
    assert made.runs == 45_680 and made.seeds == [0, 1, 2, 3, 4]
    assert list(found.claims["id"]) == [c.id for c in CLAIMS]
    assert set(found.cells["id"]) <= set(found.claims["id"])
    assert set(found.fronts["terrain"]) == {"sim_nav_1", "sim_nav_2", "sim_lan_1", "sim_lan_2",
                                            "exp_nav_1", "exp_nav_2", "exp_lan_1", "exp_lan_2"}
    assert set(found.fronts["seed"]) == {0, 1, 2, 3, 4}
