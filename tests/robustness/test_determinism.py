"""Same inputs and seeds -> byte-identical files, across runs and across --quick/full.

The wall clock is the usual culprit (zip member dates in .npz, PNG/HTML metadata),
so every run here happens at a different, patched time of day.
"""

from __future__ import annotations

import hashlib
import json
import time
from pathlib import Path

import numpy as np
import pytest

from alte.io.bags.writer import write_frames
from alte.io.points.pointfiles import write_points
from alte.types import Frame, thesis_mount

NS = 1_000_000_000
MAPPER_SETS = {
    "quadtree": ["--set", "max_points=20"],
    "alte2d": ["--set", "min_pts=3"],
    "alte3d": ["--set", "min_pts=2", "--domain=-50,-50,-50,100"],
    "octomap": ["--set", "resolution=2"],
}


def _terrain(folder: Path) -> Path:
    """The one terrain folder ``alte simulate`` wrote into ``folder``."""
    (found,) = folder.iterdir()
    return found


def _digest(path: Path) -> dict[str, str]:
    files = sorted(p for p in path.rglob("*") if p.is_file()) if path.is_dir() else [path]
    return {p.relative_to(path).as_posix() if path.is_dir() else p.name:
            hashlib.sha256(p.read_bytes()).hexdigest() for p in files}


@pytest.fixture
def clock(monkeypatch: pytest.MonkeyPatch):
    """``clock(hours)`` moves the wall clock by ``hours`` from now."""
    real = time.time

    def shift(hours: float) -> None:
        monkeypatch.setattr(time, "time", lambda: real() + 3600.0 * hours)
    return shift


@pytest.fixture(scope="module")
def small_bag(tmp_path_factory: pytest.TempPathFactory) -> Path:
    rng = np.random.default_rng(7)
    ahead = np.array([0.0, 6.0, 0.0])
    frames = [Frame(10 * NS + k * NS // 10, rng.uniform(-4.0, 4.0, (200, 3)) + ahead,
                    np.array([0.3 * k, 0.0, 3.0]), np.array([0.0, 0.0, 0.0, 1.0]))
              for k in range(5)]
    return write_frames(tmp_path_factory.mktemp("bag") / "bag", frames, thesis_mount())


@pytest.mark.parametrize("mapper", sorted(MAPPER_SETS))
def test_map_export_is_byte_identical(bags, capsys, clock, small_bag, mapper):
    tmp_path = small_bag.parent
    runs = []
    for hours in (0.0, 5.0):
        clock(hours)
        out = tmp_path / f"cells-{mapper}-{hours}.npz"
        code, text, err = bags.run_cli(capsys, "map", small_bag, "--mapper", mapper,
                                       *MAPPER_SETS[mapper], "--json", "--export", out)
        assert code == 0, err
        summary = json.loads(text)
        for key in ("elapsed_s", "wall_s", "cpu_s", "export"):  # clocks and the output path
            summary.pop(key)
        runs.append((out.read_bytes(), summary))
    assert runs[0][1] == runs[1][1]
    assert runs[0][0] == runs[1][0]


@pytest.mark.parametrize("suffix", [".npz", ".ply", ".pcd", ".laz", ".xyz"])
def test_register_output_is_byte_identical(bags, capsys, clock, small_bag, suffix):
    tmp_path = small_bag.parent
    blobs = []
    for hours in (0.0, 31.0):  # a day and more apart: dates in headers must not leak in
        clock(hours)
        out = tmp_path / f"cloud{hours}{suffix}"
        code, _, err = bags.run_cli(capsys, "register", small_bag, "--voxel", "0.25", "--out", out)
        assert code == 0, err
        blobs.append(out.read_bytes())
    assert blobs[0] == blobs[1]


def test_simulate_is_byte_identical_across_runs(bags, capsys, tmp_path):
    for out in ("a", "b"):
        code, _, err = bags.run_cli(capsys, "simulate", "sim_lan_1", "--frames", "2",
                                    "--seed", "3", "--out", tmp_path / out)
        assert code == 0, err
    first, second = _digest(_terrain(tmp_path / "a")), _digest(_terrain(tmp_path / "b"))
    assert first == second and "bag/metadata.yaml" in first


def test_simulate_seed_changes_the_noise_only(bags, capsys, tmp_path):
    for seed in ("3", "4"):
        assert bags.run_cli(capsys, "simulate", "sim_lan_1", "--frames", "2", "--seed", seed,
                            "--out", tmp_path / seed)[0] == 0
    a, b = _digest(_terrain(tmp_path / "3")), _digest(_terrain(tmp_path / "4"))
    assert a["ground_truth.ply"] == b["ground_truth.ply"]
    assert a["bag/bag.db3"] != b["bag/bag.db3"]


def test_write_points_npz_is_byte_identical(clock, tmp_path):
    cloud = np.random.default_rng(1).normal(size=(50, 3))
    clock(0.0)
    a = write_points(tmp_path / "a.npz", cloud).read_bytes()
    clock(9.0)
    b = write_points(tmp_path / "b.npz", cloud).read_bytes()
    assert a == b


# ------------------------------------------------------------------ report: --quick vs full

NOTEBOOK_PARAMS = ('OUT_DIR = "reports/scratch/robust"\nTABLES_DIR = "reports/scratch/tables"\n'
                   "SEED = 0\nPOINTS = 100\n")
NOTEBOOK_BODY = """\
import numpy as np
from pathlib import Path
from alte.fsutil import atomic_path
from alte.lab.notebook import save_figure, save_results, setup
from alte.lab.plot.figure import Caption, Plot
import matplotlib.pyplot as plt
setup()
rng = np.random.default_rng(SEED)
cloud = rng.uniform(0.0, 8.0, (POINTS, 3))
rows = [f"{k},{z:.17g}" for k, z in enumerate(cloud[:8, 2])]
with atomic_path(Path(TABLES_DIR) / "table_robust.csv", overwrite=True) as tmp:
    tmp.write_text("row,z_m\\n" + "\\n".join(rows) + "\\n")
fig, ax = plt.subplots()
ax.plot(np.sort(cloud[:, 2]))
save_figure(Plot(fig, Caption("Heights", "Point heights, sorted.")), OUT_DIR, "heights")
save_results(OUT_DIR, {"rows": rows, "mean": float(cloud.mean())})
"""


def _notebook(path: Path) -> Path:
    import nbformat

    nb = nbformat.v4.new_notebook()
    nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3",
                                 "language": "python"}
    params = nbformat.v4.new_code_cell(NOTEBOOK_PARAMS)
    params.metadata["tags"] = ["parameters"]
    nb.cells = [params, nbformat.v4.new_code_cell(NOTEBOOK_BODY)]
    path.parent.mkdir(parents=True, exist_ok=True)
    nbformat.write(nb, str(path))
    return path


@pytest.mark.slow
def test_report_tables_identical_across_runs_and_quick_full(bags, capsys, tmp_path):
    """Same parameters in --quick and full: identical tables, results and figures. Three
    runs (one of each mode, then the first again into its own folder) catch a clock, a
    mode or an earlier run leaking into a file; the notebook draws no map (the mappers'
    own determinism: the map export tests)."""
    _notebook(tmp_path / "nb" / "robust.ipynb")
    plan = tmp_path / "plan.json"
    same = {"POINTS": 400, "SEED": 5}
    plan.write_text(json.dumps([{"name": "robust", "notebook": "robust.ipynb",
                                 "quick": same, "full": same}]))
    outputs = []
    for out, mode in (("quick", ["--quick"]), ("full", []), ("quick", ["--quick"])):
        code, text, err = bags.run_cli(capsys, "report", *mode, "--plan", plan, "--notebooks",
                                       tmp_path / "nb", "--out", tmp_path / out,
                                       "--data", tmp_path / "data", "--no-warmup")
        assert code == 0, (text, err)
        run = (tmp_path / out / "latest").resolve()
        outputs.append({**_digest(run / "robust"),
                        "table": _digest(tmp_path / out / "tables")["table_robust.csv"]})
    assert outputs[0] == outputs[1] == outputs[2]
    assert set(outputs[0]) == {"results.json", "figures/heights.png", "figures/heights.json",
                               "table"}
