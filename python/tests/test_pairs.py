"""exactgeo.pair_distances: each pair against a run from its first point with its second as the target, on
vertices and surface points, every algorithm; paths; unreachable pairs; threads; the forms a and b take."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import bumpy_sheet

import exactgeo


@pytest.fixture(scope="module")
def sheet():
    return exactgeo.Mesh(*bumpy_sheet(12))


def random_points(mesh: exactgeo.Mesh, rng: np.random.Generator, count: int) -> exactgeo.SurfacePoints:
    weights = rng.dirichlet([1.0, 1.0, 1.0], size=count)
    weights[: count // 3, 2] = 0.0  # a third on edges
    weights /= weights.sum(axis=1, keepdims=True)
    return exactgeo.SurfacePoints(rng.integers(0, mesh.face_count, size=count), weights)


def targets_mode(mesh: exactgeo.Mesh, a, b, **options) -> np.ndarray:
    """Each pair as a run from a[i] that stops once b[i] is final."""
    return np.array([exactgeo.distance(mesh, a[i], targets=[b[i]], **options)[0] for i in range(len(a))])


@pytest.mark.parametrize("algorithm", exactgeo.ALGORITHMS)
def test_vertex_and_point_pairs_equal_targets_mode_runs(sheet, algorithm):
    rng = np.random.default_rng(35)
    a, b = rng.integers(0, sheet.vertex_count, size=(2, 30))
    distances = exactgeo.pair_distances(sheet, a, b, algorithm=algorithm)
    assert distances.shape == (30,) and distances.dtype == np.float64
    expected = targets_mode(sheet, a.tolist(), b.tolist(), algorithm=algorithm)
    np.testing.assert_allclose(distances, expected, rtol=0, atol=1e-14 * expected.max())
    pa, pb = random_points(sheet, rng, 20), random_points(sheet, rng, 20)
    points = exactgeo.pair_distances(sheet, pa, pb, algorithm=algorithm)
    expected = targets_mode(sheet, [pa[i] for i in range(20)], [pb[i] for i in range(20)], algorithm=algorithm)
    np.testing.assert_allclose(points, expected, rtol=0, atol=1e-14 * expected.max())


def test_a_list_may_mix_points_and_vertices(sheet):
    point = exactgeo.SurfacePoint(5, (0.2, 0.3, 0.5))
    mixed = exactgeo.pair_distances(sheet, [point, 7], [9, point])
    seven, nine = exactgeo.vertex_point(sheet, 7), exactgeo.vertex_point(sheet, 9)
    np.testing.assert_array_equal(mixed, exactgeo.pair_distances(sheet, [point, seven], [nine, point]))
    assert exactgeo.pair_distances(sheet, [point], [point])[0] == 0.0


def test_paths_run_from_a_to_b_with_the_distances_as_lengths(sheet):
    rng = np.random.default_rng(4)
    a, b = random_points(sheet, rng, 8), rng.integers(0, sheet.vertex_count, size=8)
    distances, paths = exactgeo.pair_distances(sheet, a, b, return_paths=True)
    assert len(paths) == 8
    for i, path in enumerate(paths):
        assert path.source == 0
        assert path.length == pytest.approx(distances[i], rel=1e-9)
        np.testing.assert_allclose(path.points[0], exactgeo.point_position(sheet, a[i]), atol=1e-12)
        np.testing.assert_allclose(path.points[-1], sheet.vertices[b[i]], atol=1e-12)
        pieces = np.linalg.norm(np.diff(path.points, axis=0), axis=1).sum()
        assert pieces == pytest.approx(distances[i], rel=1e-9)


def test_pairs_across_pieces_are_unreachable_and_max_distance_cuts_off(sheet):
    vertices, faces = bumpy_sheet(4)
    apart = exactgeo.Mesh(np.vstack([vertices, vertices + [3.0, 0, 0]]), np.vstack([faces, faces + len(vertices)]))
    n = len(vertices)
    distances, paths = exactgeo.pair_distances(apart, [0, 0, n + 1], [n + 2, 5, 3], return_paths=True)
    assert np.isinf(distances[0]) and np.isinf(distances[2]) and np.isfinite(distances[1])
    assert len(paths[0].points) == 0 and paths[0].length == np.inf
    rng = np.random.default_rng(8)
    a, b = rng.integers(0, sheet.vertex_count, size=(2, 20))
    whole = exactgeo.pair_distances(sheet, a, b)
    limit = float(np.median(whole))
    cut = exactgeo.pair_distances(sheet, a, b, max_distance=limit)
    near = whole <= limit
    np.testing.assert_array_equal(cut[near], whole[near])
    assert np.isinf(cut[~near]).all() and (~near).any()


def test_the_thread_count_changes_nothing(sheet):
    rng = np.random.default_rng(2)
    a, b = rng.integers(0, sheet.vertex_count, size=(2, 25))
    one = exactgeo.pair_distances(sheet, a, b, threads=1)
    np.testing.assert_array_equal(one, exactgeo.pair_distances(sheet, a, b, threads=2))
    np.testing.assert_array_equal(one, exactgeo.pair_distances(sheet, a, b, threads=3))
    np.testing.assert_array_equal(one, exactgeo.pair_distances(sheet, a.astype(np.int16), b, threads=None))


def test_bad_pairs_are_named(sheet):
    with pytest.raises(ValueError, match=r"^a and b must have the same length \(a has 2 points, b 1\)$"):
        exactgeo.pair_distances(sheet, [0, 1], [2])
    with pytest.raises(ValueError, match=r"^b 1: vertex 999 is out of range"):
        exactgeo.pair_distances(sheet, [0, 1], [2, 999])
    with pytest.raises(ValueError, match=r"^a 0: face 9999 is out of range"):
        exactgeo.pair_distances(sheet, [exactgeo.SurfacePoint(9999)], [0])
    with pytest.raises(TypeError, match="unexpected keyword argument 'radius'"):
        exactgeo.pair_distances(sheet, [0], [1], radius=1.0)
    assert exactgeo.pair_distances(sheet, [], []).shape == (0,)
