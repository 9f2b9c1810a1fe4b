"""The command line stays light: ``alte --help``, ``--version`` and ``alte info BAG``
load none of the heavy stacks (each command imports what it runs), and the help that
``alte --help`` shows without importing a command is the command's own."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest
from support.bagtools import TS, write_ros2

from alte import __version__
from alte.cli import COMMANDS, build_parser
from alte.io.bags.pointcloud2 import encode_pointcloud2
from alte.io.bags.writer import BagSettings, write_bag
from alte.types import thesis_mount

#: What a command that only reads or prints must not load: the lab (report, studies),
#: the mappers' numba kernels, open3d (~200 MB), Dask and pyvista/VTK.
HEAVY = ["alte.lab.report", "alte.lab.studies", "open3d", "numba", "dask", "distributed", "pyvista",
         "vtk", "pandas"]
NS = 1_000_000_000


def _loaded(argv: list[str], before: str = "") -> tuple[list[str], str]:
    """The heavy modules loaded by ``alte ARGV`` in a fresh interpreter (after the
    statement ``before``), and its stdout."""
    code = (f"import json, sys\n{before}\nfrom alte.cli import main\n"
            f"try:\n    main({argv!r})\nexcept SystemExit:\n    pass\n"
            f"print(json.dumps([h for h in {HEAVY!r} if h in sys.modules]))")
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True, timeout=600)
    *out, last = run.stdout.splitlines()
    loaded: list[str] = json.loads(last)
    return loaded, "\n".join(out)


@pytest.fixture(scope="module")
def bags(tmp_path_factory):
    """A bag with a pose topic, and one without (``alte info`` then names the odometry)."""
    root = tmp_path_factory.mktemp("bags")
    clouds = [(NS + k * NS // 10, np.full((4, 3), float(k))) for k in range(3)]
    stamps = NS + np.arange(21) * NS // 100
    pos, quat = np.zeros((21, 3)), np.tile([0.0, 0.0, 0.0, 1.0], (21, 1))
    posed = write_bag(root / "posed", clouds, stamps, pos, quat, thesis_mount(),
                      BagSettings(cloud_topic="/lidar", pose_topic="/vicon"))
    bare = write_ros2(root / "bare", [("/lidar", "sensor_msgs/msg/PointCloud2", s,
                                       encode_pointcloud2(p, s, "lidar", TS)) for s, p in clouds])
    return posed, bare


def test_help_and_version_import_nothing_heavy() -> None:
    loaded, out = _loaded(["--help"])
    assert loaded == []
    assert all(name in out for name in COMMANDS)  # every command listed, none imported
    assert _loaded(["--version"]) == ([], f"alte {__version__}")


def test_info_of_a_bag_imports_nothing_heavy(bags) -> None:
    posed, bare = bags
    loaded, out = _loaded(["info", str(posed)])
    assert loaded == [] and "pose:      /vicon" in out
    loaded, out = _loaded(["info", str(bare), "--json"])
    assert loaded == [] and "odometry" in json.loads(out)["pose_source"]


def test_the_check_sees_a_heavy_import() -> None:
    assert _loaded(["--version"], before="import pandas")[0] == ["pandas"]


def test_every_command_registers_the_help_alte_help_shows() -> None:
    full = build_parser("*")
    light = build_parser()
    for parser in (full, light):
        sub = next(a for a in parser._actions if a.dest == "command")
        assert list(sub.choices) == list(COMMANDS)
    helps = {parser: {a.dest: a.help for a in next(
        a for a in parser._actions if a.dest == "command")._choices_actions}
        for parser in (full, light)}
    assert helps[full] == helps[light] == {name: summary for name, (_, summary) in
                                           COMMANDS.items()}


def test_an_unknown_command_lists_the_commands(capsys) -> None:
    from alte.cli import main

    with pytest.raises(SystemExit) as stop:
        main(["mapp", "x"])
    assert stop.value.code == 2
    err = capsys.readouterr().err
    assert "invalid choice: 'mapp'" in err and "info" in err


def test_the_bench_row_of_the_light_commands(bags) -> None:
    from bench.memory import LIGHT_CEILINGS_MB, light_memory

    rows = light_memory(bags[0])
    assert [r.case.split(" peak")[0] for r in rows] == ["alte --version", "alte info BAG"]
    assert all(r.met and r.peer < r.ours < max(LIGHT_CEILINGS_MB.values()) for r in rows)
