"""Ground-truth PLY: per-triangle object ids survive a round trip; bad files are refused."""

import numpy as np
import pytest

from alte.errors import AlteError, PointFileError
from alte.sim.groundtruth import (
    load_ground_truth,
    mesh_distance,
    read_ground_truth,
    write_ground_truth,
)
from alte.sim.scene import SceneBuilder


@pytest.fixture
def scene():
    b = SceneBuilder()
    b.ground("floor", (-5, -5, 5, 5))
    b.slab("house front", "building", (1, 1), (2, 2), z=(0.0, 3.0))
    b.cylinder("post", "pillar", (-2, -2), 0.2, z=(0.0, 1.0), segments=8)
    return b.build()


def test_round_trip_keeps_mesh_ids_and_names(tmp_path, scene):
    path = write_ground_truth(tmp_path / "ground_truth.ply", scene)
    back = load_ground_truth(tmp_path)
    assert np.array_equal(back.vertices, scene.vertices)
    assert np.array_equal(back.triangles, scene.triangles)
    assert np.array_equal(back.object_ids, scene.object_ids)
    assert np.array_equal(back.class_ids, scene.class_ids)
    assert back.objects == scene.objects
    again = write_ground_truth(tmp_path / "again.ply", back)
    assert again.read_bytes() == path.read_bytes()


def test_open3d_reads_the_geometry(tmp_path, scene):
    import open3d as o3d

    path = write_ground_truth(tmp_path / "gt.ply", scene)
    mesh = o3d.io.read_triangle_mesh(str(path))
    assert len(mesh.triangles) == len(scene.triangles)
    assert np.allclose(np.asarray(mesh.vertices), scene.vertices)


def test_refuses_to_overwrite(tmp_path, scene):
    write_ground_truth(tmp_path / "gt.ply", scene)
    with pytest.raises(AlteError, match="already exists"):
        write_ground_truth(tmp_path / "gt.ply", scene)


@pytest.mark.parametrize(("mangle", "match"), [
    (lambda raw: raw[:-7], "truncated"),
    (lambda raw: b"solid x\n" + raw, "not a PLY"),
    (lambda raw: raw.replace(b"comment alte ground truth", b"comment something else   "),
     "not an alte ground-truth PLY"),
])
def test_bad_files_raise(tmp_path, scene, mangle, match):
    path = write_ground_truth(tmp_path / "gt.ply", scene)
    path.write_bytes(mangle(path.read_bytes()))
    with pytest.raises(PointFileError, match=match):
        read_ground_truth(path)


def test_missing_file_raises(tmp_path):
    with pytest.raises(PointFileError, match="cannot read ground truth"):
        load_ground_truth(tmp_path)


def test_mesh_distance(scene):
    d = mesh_distance(np.array([[4.0, 4.0, 0.5], [1.0, 1.0, 3.25], [0.0, 3.0, 0.0]]), scene)
    assert np.allclose(d, [0.5, 0.25, 0.0], atol=1e-6)
