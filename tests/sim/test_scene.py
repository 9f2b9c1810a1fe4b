"""Scene building blocks: closed, outward-facing convex parts with object ids."""

import numpy as np
import pytest

from alte.sim.scene import CLASSES, SceneBuilder


def _signed_volume(vertices, triangles):
    tri = vertices[triangles]
    return np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum() / 6.0


@pytest.mark.parametrize(("make", "volume"), [
    (lambda b: b.box("b", "building", (1, 2, 3), (2, 3, 4), yaw_deg=30), 24.0),
    (lambda b: b.slab("s", "wall", (0, 0), (1, 2), z=(1.0, 4.0)), 6.0),
    (lambda b: b.gable("r", "building", (0, 0), size=(4.0, 2.0), z=(1.0, 2.0)), 4.0),
    (lambda b: b.cylinder("c", "pillar", (5, 5), 1.0, z=(0.0, 2.0), segments=64), 2 * np.pi),
])
def test_parts_are_closed_outward_and_have_the_right_volume(make, volume):
    b = SceneBuilder()
    make(b)
    scene = b.build()
    # outward orientation gives a positive signed volume equal to the solid's volume
    assert _signed_volume(scene.vertices, scene.triangles) == pytest.approx(volume, rel=0.01)
    edges = np.sort(scene.triangles[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)
    _, count = np.unique(edges, axis=0, return_counts=True)
    assert np.all(count == 2)  # watertight


def test_object_and_class_ids_per_triangle():
    b = SceneBuilder()
    b.ground("floor", (-1, -1, 1, 1))
    b.box("car", "car", (0, 0, 0.5), (1, 1, 1))
    b.sphere("ball", "debris", (3, 0, 1), 0.5)
    scene = b.build()
    assert np.array_equal(np.unique(scene.object_ids), [0, 1, 2])
    assert np.sum(scene.object_ids == 1) == 12
    assert set(scene.class_ids.tolist()) == {CLASSES.index(c) for c in ("ground", "car", "debris")}
    assert scene.labels == {0: "floor", 1: "car", 2: "ball"}
    assert scene.classes[1] == "car"
    assert np.allclose(scene.bounds(), [-1, -1, 0, 3.5, 1, 1.5], atol=1e-9)


def test_builder_errors():
    with pytest.raises(ValueError, match="unknown class 'tank'"):
        SceneBuilder().box("x", "tank", (0, 0, 0), (1, 1, 1))
    with pytest.raises(ValueError, match="at least one object"):
        SceneBuilder().build()
