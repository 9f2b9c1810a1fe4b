"""Tests of ``alte map`` on a small point file and a small bag."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from alte.cli import main
from alte.commands.map import parse_domain
from alte.commands.options import parse_key_values, parse_origin
from alte.errors import ParameterError
from alte.mappers.alte2d import Alte2D
from alte.mappers.domain import Domain
from alte.mappers.quadtree import Quadtree
from alte.pipeline import DomainPolicy
from alte.types import Frame, Mount


def terrain(n: int = 2000, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    xy = rng.uniform(0, 16, (n, 2))
    return np.column_stack([xy, np.where(xy[:, 0] > 8, 2.0, 0.0) + rng.normal(0, 0.01, n)])


def cube_over(points: np.ndarray) -> dict[str, float]:
    """The domain the data policy must give, by hand: the cube anchored at the points'
    minimum corner whose edge is their longest extent (up to a relative 1e-9 slack)."""
    lo, hi = points.min(axis=0), points.max(axis=0)
    return {"xmin": lo[0], "ymin": lo[1], "zmin": lo[2], "size": float((hi - lo).max())}


@pytest.fixture
def cloud_file(tmp_path: Path) -> Path:
    path = tmp_path / "cloud.npz"
    np.savez(path, points=terrain())
    return path


def run_json(capsys, *argv: str) -> dict:
    assert main(["map", *argv, "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def test_point_file_json_summary(capsys, cloud_file: Path) -> None:
    out = run_json(capsys, str(cloud_file), "--mapper", "alte2d", "--set", "kappa=0.01",
                   "--set", "max_res=5")
    assert out["domain"] == pytest.approx(cube_over(terrain()), rel=1e-8)
    ref = Alte2D(Domain(**out["domain"]), kappa=0.01, max_res=5)
    ref.build(terrain())
    assert out["mapper"] == "alte2d" and out["params"]["kappa"] == 0.01
    assert out["frames"] == 1 and out["points"] == 2000
    assert out["basis_functions"] == ref.basis_functions
    assert out["occupied_cells"] == int(ref.cells().occupied.sum())
    assert out["memory_bytes"] == ref.memory_bytes
    assert 0 < out["elapsed_s"] < 10


def test_voxel_reduces_points(capsys, cloud_file: Path) -> None:
    out = run_json(capsys, str(cloud_file), "--mapper", "quadtree", "--voxel", "1.0")
    assert 0 < out["points"] <= 16 * 16 * 3


def test_export_npz_and_overwrite(capsys, cloud_file: Path, tmp_path: Path) -> None:
    target = tmp_path / "cells.npz"
    argv = ["map", str(cloud_file), "--mapper", "quadtree", "--set", "max_points=50",
            "--export", str(target)]
    assert main(argv) == 0
    lo = terrain().min(axis=0)
    size = float(np.ptp(terrain(), axis=0).max())
    ref = Quadtree(Domain(*lo, size * (1 + 1e-9) + 1e-9), max_points=50)
    ref.build(terrain())
    with np.load(target) as data:
        assert set(data.files) == {"centers", "sizes", "value", "occupied", "level"}
        assert np.array_equal(data["level"], ref.cells().level)
        assert np.allclose(data["centers"], ref.cells().centers, equal_nan=True)
    capsys.readouterr()
    assert main(argv) == 2
    assert "already exists" in capsys.readouterr().err
    assert main([*argv, "--force"]) == 0


@pytest.mark.parametrize(("extra", "message"), [
    (["--mapper", "kriging"], "unknown mapper 'kriging'; valid: quadtree"),
    (["--mapper", "alte2d", "--set", "tau=1"], "valid: criterion, kappa, max_res, min_pts"),
    (["--mapper", "alte2d", "--set", "domain=0,0,1"], "unknown parameter(s) domain"),
    (["--mapper", "alte2d", "--domain", "0,0,-1"], "--domain '0,0,-1'"),
    (["--mapper", "alte2d", "--domain", "everywhere"], "--domain 'everywhere'"),
    (["--mapper", "alte2d", "--domain", "control"], "no control volume"),
    (["--mapper", "alte2d", "--frames", "0"], "--frames"),
    (["--mapper", "alte2d", "--set", "kappa"], "expected KEY=VALUE"),
    (["--mapper", "alte2d", "--set", "kappa=-1"], "kappa=-1.0 out of range"),
    (["--mapper", "alte2d", "--origin", "1,2"], "--origin"),
    (["--mapper", "alte2d", "--voxel", "0"], "--voxel"),
    (["--mapper", "alte2d", "--export", "cells.csv"], "writes .npz (not .csv)"),
    (["--mapper", "alte2d", "--export", "tree.bt"], "writes .npz (not .bt)"),
])
def test_errors_are_one_line(capsys, cloud_file: Path, tmp_path: Path, extra, message) -> None:
    extra = [str(tmp_path / e) if e.endswith((".csv", ".bt")) else e for e in extra]
    assert main(["map", str(cloud_file), *extra]) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1
    assert not (tmp_path / "tree.bt").exists()


def test_export_bt_through_octomap(capsys, tmp_path: Path) -> None:
    pytest.importorskip("alte.mappers.octomap")
    cloud = tmp_path / "small.npz"
    np.savez(cloud, points=terrain(300) + np.array([0.0, 0.0, 1.0]))
    target = tmp_path / "tree.bt"
    argv = ["map", str(cloud), "--mapper", "octomap", "--set", "resolution=1",
            "--origin", "8,8,10", "--export", str(target)]
    assert main(argv) == 0
    assert target.is_file() and target.stat().st_size > 0
    capsys.readouterr()
    assert main(argv) == 2 and "exists" in capsys.readouterr().err
    assert main([*argv, "--force"]) == 0


def test_missing_input(capsys, tmp_path: Path) -> None:
    assert main(["map", str(tmp_path / "nothing.bag"), "--mapper", "alte2d"]) == 2
    assert "nothing.bag" in capsys.readouterr().err


def test_parsers() -> None:
    assert parse_key_values(["a=1", " b = x=y "], "--set") == {"a": "1", "b": "x=y"}
    assert np.array_equal(parse_origin("1,2,3"), [1.0, 2.0, 3.0])
    assert parse_domain("Data") is DomainPolicy.DATA
    assert parse_domain("1,2,3") == Domain(1.0, 2.0, 0.0, 3.0)
    with pytest.raises(ParameterError, match=r"^--set '=3': expected KEY=VALUE"):
        parse_key_values(["=3"], "--set")
    with pytest.raises(ParameterError, match="--origin"):
        parse_origin("a,b,c")


def test_bag_is_mapped_frame_by_frame(capsys, tmp_path: Path) -> None:
    io = pytest.importorskip("alte.io")
    registration = pytest.importorskip("alte.registration")
    rng = np.random.default_rng(4)
    frames = []
    for i in range(4):
        position = np.array([2.0 + 3.0 * i, 8.0, 10.0])
        xy = rng.uniform(-4, 4, (300, 2))
        step = np.where(xy[:, 0] + position[0] > 8, 2.0, 0.0)  # a 2 m step at x = 8
        ground = np.column_stack([xy, step - 10.0])
        frames.append(Frame(stamp=(i + 1) * 100_000_000, points=ground, position=position,
                            quaternion=np.array([0.0, 0.0, 0.0, 1.0])))
    bag = io.write_frames(tmp_path / "flight", frames, Mount())
    out = run_json(capsys, str(bag), "--mapper", "alte2d", "--domain=-4,0,20",
                   "--set", "max_res=4", "--set", "min_pts=5")
    assert out["frames"] == 4 and out["points"] == 1200
    assert out["domain"] == {"xmin": -4.0, "ymin": 0.0, "zmin": 0.0, "size": 20.0}
    assert out["domain_policy"] == "explicit"
    reg = list(registration.register_frames(frames, Mount()))
    ref = Alte2D(Domain(-4, 0, 0, 20), max_res=4, min_pts=5)
    ref.build(np.concatenate([pts for _f, pts, _o in reg]))
    assert out["basis_functions"] == ref.basis_functions > 4
    assert out["occupied_cells"] == int(ref.cells().occupied.sum())


@pytest.mark.parametrize("mapper", ["quadtree", "octomap", "alte2d", "alte3d"])
def test_bag_without_domain_maps_with_every_mapper(capsys, tmp_path: Path, mapper) -> None:
    """No ``--domain``: a plain bag's domain is the cube over its registered frames."""
    from alte import io

    rng = np.random.default_rng(7)
    frames = [Frame(stamp=(i + 1) * 100_000_000, points=rng.uniform(-3, 3, (200, 3)),
                    position=np.array([2.0 * i, 1.0, 5.0]), quaternion=np.array([0, 0, 0, 1.0]))
              for i in range(3)]
    bag = io.write_frames(tmp_path / "flight", frames, Mount(), dtype=np.float64)
    out = run_json(capsys, str(bag), "--mapper", mapper)
    assert out["frames"] == 3 and out["points"] == 600 and out["points_outside"] == 0
    assert out["basis_functions"] > 0
    # 600 scattered points are too sparse for 3D-ALTE's density rule to occupy a cell
    assert out["occupied_cells"] > 0 or mapper == "alte3d"
    if mapper == "octomap":  # no domain: it keys voxels around a local origin
        assert out["domain"] is None and out["domain_policy"] == "none (fixed key space)"
    else:
        # identity attitude and mount: each frame's points shifted by its position
        points = np.concatenate([f.points + f.position for f in frames])
        assert out["domain_policy"] == "data"
        assert out["domain"] == pytest.approx(cube_over(points), rel=1e-8)
