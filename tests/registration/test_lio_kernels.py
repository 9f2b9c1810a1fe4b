"""The LIO local map's kernels: plane fits with the same flatness, normals and centroids as
numpy's mean, covariance and LAPACK ``eigh`` give, on planes, lines, blobs and degenerate
rows; two neighbour lists merged as a stable sort orders them."""

import numpy as np
import pytest

from alte.registration.lio_kernels import merge_nearest, plane_fits


def _lapack(points, idx, thickness):
    """The fits as numpy computes them (batched ``eigh``, eigenvalues ascending)."""
    nbrs = points[idx]
    centre = nbrs.mean(axis=1)
    centred = nbrs - centre[:, None, :]
    values, vectors = np.linalg.eigh(np.einsum("nki,nkj->nij", centred, centred)
                                     / idx.shape[1])
    spread = np.sqrt(np.maximum(values, 0.0))
    flat = (spread[:, 0] < thickness) & (spread[:, 1] > 3.0 * thickness)
    return flat, vectors[:, :, 0], centre


def _neighbourhoods(rows, k, rng):
    """``rows`` groups of ``k`` points: noisy and exact planes, lines, blobs, one point
    repeated, each turned and scaled at random."""
    groups = []
    for row in range(rows):
        local = rng.normal(size=(k, 3))
        kind = row % 5
        if kind == 0:
            local[:, 2] *= 0.01
        elif kind == 1:
            local[:, 1:] *= 1e-3
        elif kind == 2:
            local[:] = local[0]
        elif kind == 3:
            local[:, 2] = 0.0
        turn, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        groups.append(rng.uniform(-50, 50, 3) + local @ turn.T * rng.uniform(0.1, 3.0))
    return np.vstack(groups)


@pytest.mark.parametrize("k", [5, 20])
def test_fits_match_numpys_eigh(k):
    rng = np.random.default_rng(7)
    points = _neighbourhoods(1000, k, rng)
    idx = rng.permutation(len(points))
    points[idx] = points.copy()  # rows of idx point anywhere in the array
    idx = idx.reshape(-1, k)
    flat, normal, centre = plane_fits(points, idx, 0.05)
    want_flat, want_normal, want_centre = _lapack(points, idx, 0.05)
    assert np.array_equal(flat, want_flat)
    assert 300 < flat.sum() < 500  # the planes of kinds 0 and 3 (blobs: too thick)
    assert np.allclose(centre, want_centre, rtol=0, atol=1e-12)
    assert np.allclose(np.linalg.norm(normal, axis=1), 1.0, rtol=0, atol=1e-12)
    assert np.allclose(np.abs(np.einsum("ij,ij->i", normal[flat], want_normal[flat])), 1.0,
                       rtol=0, atol=1e-12)


def test_a_tilted_plane_gets_its_normal_and_a_line_is_not_flat():
    rng = np.random.default_rng(1)
    plane = np.c_[rng.uniform(-2, 2, (20, 2)), np.zeros(20)]
    plane[:, 2] = 0.5 * plane[:, 0]  # z = x / 2
    line = np.c_[np.linspace(0, 3, 20), np.zeros((20, 2))]
    points = np.vstack([plane, line])
    flat, normal, _ = plane_fits(points, np.arange(40).reshape(2, 20), 0.05)
    assert flat.tolist() == [True, False]
    assert np.allclose(np.abs(normal[0]), np.array([0.5, 0.0, 1.0]) / np.sqrt(1.25))


def test_merged_neighbours_keep_the_first_trees_rows_first_on_equal_distances():
    """Both trees' lists merged as a stable sort of them side by side orders them: equal
    distances (a point duplicated across the two trees) give the packed tree's row
    first, missing neighbours (inf) come last."""
    inf = np.inf
    first = (np.array([[0.5, 1.0, inf], [0.1, 0.2, 0.3]]), np.array([[0, 1, 9], [2, 3, 4]]))
    second = (np.array([[0.5, 0.7, inf], [inf, inf, inf]]), np.array([[5, 6, 9], [9, 9, 9]]))
    dist, idx = merge_nearest(first, second)
    both_d, both_i = np.hstack([first[0], second[0]]), np.hstack([first[1], second[1]])
    order = np.argsort(both_d, axis=1, kind="stable")[:, :3]
    assert np.array_equal(dist, np.take_along_axis(both_d, order, axis=1))
    assert np.array_equal(idx, np.take_along_axis(both_i, order, axis=1))
    assert idx.tolist() == [[0, 5, 6], [2, 3, 4]]
