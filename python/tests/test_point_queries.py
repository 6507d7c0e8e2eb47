"""Queries at any surface point after one run: GeodesicSolver.solve(..., keep_windows=True), then distance_at
and path_to_point. The reference is a run with the same points as targets (the C++ suites check both against
CGAL); every form of points that targets= takes is accepted."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import MESH_DIR, bumpy_sheet

import exactgeo


def random_points(mesh: exactgeo.Mesh, count: int, seed: int) -> exactgeo.SurfacePoints:
    """Inside random faces, a third of them on an edge."""
    rng = np.random.default_rng(seed)
    weights = rng.dirichlet((1, 1, 1), count)
    on_edge = np.arange(count) % 3 == 0
    weights[on_edge, rng.integers(0, 3, on_edge.sum())] = 0
    weights /= weights.sum(axis=1, keepdims=True)
    return exactgeo.SurfacePoints(rng.integers(0, mesh.face_count, count), weights)


def expect_like_targets(mesh: exactgeo.Mesh, sources, points, **options) -> np.ndarray:
    solver = exactgeo.GeodesicSolver(mesh)
    result = solver.solve(sources, keep_windows=True, **options)
    assert result.stats.kept_windows > 0 and result.stats.kept_window_bytes > 40 * result.stats.kept_windows
    queried = solver.distance_at(points)
    expected = exactgeo.GeodesicSolver(mesh).solve(sources, points, **options).target_distances
    assert queried.dtype == np.float64 and queried.shape == expected.shape
    np.testing.assert_array_equal(np.isinf(queried), np.isinf(expected))
    finite = np.isfinite(expected)
    largest = result.distances[np.isfinite(result.distances)].max()
    assert np.abs(queried[finite] - expected[finite]).max(initial=0) <= 1e-14 * largest
    return queried


@pytest.mark.parametrize("threads", [1, 2, 3])
@pytest.mark.parametrize("algorithm", exactgeo.ALGORITHMS)
def test_distance_at_equals_a_run_with_the_points_as_targets(algorithm, threads):
    mesh = exactgeo.Mesh(*bumpy_sheet(14, seed=3))
    expect_like_targets(mesh, [0, 77], random_points(mesh, 500, seed=1), algorithm=algorithm, threads=threads)


@pytest.mark.parametrize("scale", [2.0**-990, 1.0, 2.0**990])
def test_tiny_and_huge_meshes_scale_exactly(scale):
    vertices, faces = exactgeo.make_bumpy_torus(30, 12)
    points = random_points(exactgeo.Mesh(vertices, faces), 300, seed=2)
    unit = expect_like_targets(exactgeo.Mesh(vertices, faces), 5, points)
    scaled = expect_like_targets(exactgeo.Mesh(vertices * scale, faces), 5, points)
    np.testing.assert_array_equal(scaled, unit * scale)


@pytest.mark.skipif(not (MESH_DIR / "spot.obj").exists(), reason="../shared/meshes not found")
def test_on_a_shared_mesh_from_point_sources_and_with_a_cut_off():
    mesh = exactgeo.Mesh.load(MESH_DIR / "spot.obj")
    points = random_points(mesh, 1000, seed=4)
    sources = exactgeo.SurfacePoints([10, 2000], [[0.2, 0.3, 0.5], [0.5, 0.5, 0.0]])
    expect_like_targets(mesh, sources, points)
    cut = expect_like_targets(mesh, sources, points, max_distance=0.3)
    assert 0 < np.isinf(cut).sum() < len(cut)


def test_points_come_in_every_form_targets_take():
    mesh = exactgeo.Mesh(*bumpy_sheet(8))
    solver = exactgeo.GeodesicSolver(mesh)
    distances = solver.solve(0, keep_windows=True).distances
    np.testing.assert_array_equal(solver.distance_at([3, 40]), distances[[3, 40]])
    np.testing.assert_array_equal(solver.distance_at(np.array([40], dtype=np.int16)), distances[[40]])
    point = exactgeo.SurfacePoint(5, (0.2, 0.3, 0.5))
    one = solver.distance_at(point)
    assert one.shape == (1,)
    mixed = solver.distance_at([point, 40, exactgeo.vertex_point(mesh, 3)])
    np.testing.assert_array_equal(mixed, [one[0], distances[40], distances[3]])
    assert solver.distance_at(exactgeo.SurfacePoints([], np.empty((0, 3)))).shape == (0,)


def test_paths_reach_the_point_and_measure_its_distance():
    mesh = exactgeo.Mesh(*bumpy_sheet(12))
    solver = exactgeo.GeodesicSolver(mesh)
    solver.solve([0, 100], keep_windows=True)
    points = random_points(mesh, 60, seed=5)
    distances = solver.distance_at(points)
    for i in range(len(points)):
        path = solver.path_to_point(points[i])
        assert path.length == pytest.approx(distances[i], rel=1e-12)
        np.testing.assert_allclose(path.points[-1], exactgeo.point_position(mesh, points[i]), atol=1e-12)
        np.testing.assert_allclose(path.points[0], mesh.vertices[[0, 100][path.source]], atol=1e-12)
    assert solver.path_to_point(7).length == solver.path_to_vertex(7).length


def test_queries_need_a_run_that_kept_its_windows():
    mesh = exactgeo.Mesh(*bumpy_sheet(4))
    solver = exactgeo.GeodesicSolver(mesh)
    with pytest.raises(ValueError, match="distance_at needs the windows of the last run"):
        solver.distance_at(0)
    solver.solve(0)
    with pytest.raises(ValueError, match="keep_windows"):
        solver.path_to_point(exactgeo.SurfacePoint(0))
    assert solver.solve(0).stats.kept_window_bytes == 0
    solver.solve(0, keep_windows=True)
    with pytest.raises(ValueError, match="point 1: face 999 is out of range"):
        solver.distance_at(exactgeo.SurfacePoints([0, 999], [[1.0, 0, 0]] * 2))
