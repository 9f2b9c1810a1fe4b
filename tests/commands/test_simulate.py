"""``alte simulate``: one terrain, all terrains, cache message, errors."""

import json

from alte.cli import main
from alte.sim import TERRAINS


def test_simulate_one_then_up_to_date(tmp_path, capsys):
    assert main(["simulate", "sim_lan_1", "--out", str(tmp_path), "--frames", "3"]) == 0
    out = capsys.readouterr().out
    assert "sim_lan_1: 3 frames" in out and "simulated in" in out
    assert main(["simulate", "sim_lan_1", "--out", str(tmp_path), "--frames", "3"]) == 0
    assert "up to date" in capsys.readouterr().out
    meta = json.loads((tmp_path / "sim_lan_1-3f" / "scenario.json").read_text())
    assert meta["storage"] == "sqlite3" and meta["frames_requested"] == 3


def test_simulate_all_with_mcap(tmp_path, capsys):
    assert main(["simulate", "all", "--out", str(tmp_path), "--frames", "2", "--seed", "5",
                 "--storage", "mcap"]) == 0
    out = capsys.readouterr().out
    for name in TERRAINS:
        assert f"{name}: 2 frames" in out
        assert (tmp_path / f"{name}-2f-s5" / "bag" / "bag.mcap").is_file()
        assert json.loads((tmp_path / f"{name}-2f-s5" / "scenario.json").read_text())["seed"] == 5


def test_unknown_terrain_is_a_one_line_error(tmp_path, capsys):
    assert main(["simulate", "moon", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert "unknown terrain 'moon'" in err and "exp_lan_2" in err


def test_bad_frames_is_an_error(tmp_path, capsys):
    assert main(["simulate", "sim_nav_1", "--out", str(tmp_path), "--frames", "0"]) == 2
    assert "frames=0" in capsys.readouterr().err
