"""exactgeo.locate: closed forms, points on the surface, the dtypes and shapes it takes, errors, threads, the
GIL, and the located points as sources and targets. Exactness against a search of every face is the C++
suite's (tests/test_locate.cpp)."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import bumpy_sheet, longest_pause_of_python_while

import exactgeo


@pytest.fixture(scope="module")
def flat():
    return exactgeo.Mesh(*exactgeo.make_grid(8, 5, 2.0, 1.25))


@pytest.fixture(scope="module")
def sheet():
    return exactgeo.Mesh(*bumpy_sheet(12))


def test_above_a_flat_grid_the_closest_point_is_straight_below(flat):
    rng = np.random.default_rng(1)
    xyz = np.column_stack([rng.uniform(0, 2, 200), rng.uniform(0, 1.25, 200), rng.uniform(-1, 1, 200)])
    points, distances = exactgeo.locate(flat, xyz)
    assert isinstance(points, exactgeo.SurfacePoints) and len(points) == 200
    assert distances.dtype == np.float64 and distances.shape == (200,)
    np.testing.assert_allclose(distances, np.abs(xyz[:, 2]), rtol=1e-14, atol=1e-15)
    below = xyz.copy()
    below[:, 2] = 0
    np.testing.assert_allclose(exactgeo.point_position(flat, points), below, rtol=0, atol=1e-15)


def test_beyond_the_border_the_closest_point_is_on_it(flat):
    points, distances = exactgeo.locate(flat, [[-1.0, 0.5, 0.0], [3.0, 2.25, 0.0], [1.0, -0.5, 2.0]])
    np.testing.assert_allclose(distances, [1.0, np.sqrt(2.0), np.sqrt(0.25 + 4)], rtol=1e-15)
    np.testing.assert_allclose(exactgeo.point_position(flat, points), [[0, 0.5, 0], [2, 1.25, 0], [1, 0, 0]],
                               atol=1e-15)


def test_points_on_the_surface_are_found_where_they_are(sheet):
    rng = np.random.default_rng(2)
    weights = rng.dirichlet([1, 1, 1], size=300)
    on_surface = exactgeo.SurfacePoints(rng.integers(0, sheet.face_count, 300), weights)
    xyz = exactgeo.point_position(sheet, on_surface)
    points, distances = exactgeo.locate(sheet, xyz)
    assert distances.max() < 1e-15
    np.testing.assert_allclose(exactgeo.point_position(sheet, points), xyz, rtol=0, atol=1e-15)


def test_located_points_are_valid_and_no_farther_than_any_vertex(sheet):
    rng = np.random.default_rng(3)
    xyz = rng.uniform(-0.5, 1.5, size=(500, 3))
    points, distances = exactgeo.locate(sheet, xyz)
    assert np.all((points.faces >= 0) & (points.faces < sheet.face_count))
    assert np.all((points.barycentric >= 0) & (points.barycentric <= 1))
    np.testing.assert_allclose(points.barycentric.sum(axis=1), 1, rtol=0, atol=1e-15)
    np.testing.assert_allclose(np.linalg.norm(xyz - exactgeo.point_position(sheet, points), axis=1), distances,
                               rtol=1e-14)
    nearest_vertex = np.linalg.norm(xyz[:, None, :] - sheet.vertices[None, :, :], axis=2).min(axis=1)
    assert np.all(distances <= nearest_vertex * (1 + 1e-15))


@pytest.mark.parametrize("dtype", [np.float16, np.float32, np.float64, np.longdouble, np.int32, np.int64, np.uint8])
def test_any_real_dtype(sheet, dtype):
    xyz = np.array([[0, 0, 1], [1, 1, 2], [0, 1, 0]])  # exact in every dtype
    expected_points, expected = exactgeo.locate(sheet, xyz.astype(np.float64))
    points, distances = exactgeo.locate(sheet, xyz.astype(dtype))
    np.testing.assert_array_equal(points.faces, expected_points.faces)
    np.testing.assert_array_equal(points.barycentric, expected_points.barycentric)
    np.testing.assert_array_equal(distances, expected)


def test_shapes(sheet):
    one_points, one = exactgeo.locate(sheet, (0.25, 0.5, 1.0))
    many_points, many = exactgeo.locate(sheet, [[0.25, 0.5, 1.0]])
    assert len(one_points) == 1 and one.shape == (1,)
    assert one_points[0] == many_points[0] and one[0] == many[0]
    fortran = np.asfortranarray(np.random.default_rng(4).uniform(size=(20, 3)))
    np.testing.assert_array_equal(exactgeo.locate(sheet, fortran)[1], exactgeo.locate(sheet, fortran.copy())[1])
    empty_points, empty = exactgeo.locate(sheet, np.empty((0, 3)))
    assert len(empty_points) == 0 and empty.shape == (0,)


def test_errors_name_what_is_wrong(sheet):
    with pytest.raises(ValueError, match=r"point 1 has a non-finite coordinate"):
        exactgeo.locate(sheet, [[0, 0, 0], [0, np.nan, 0]])
    with pytest.raises(ValueError, match=r"point 0 has a non-finite coordinate"):
        exactgeo.locate(sheet, [np.inf, 0, 0])
    with pytest.raises(ValueError, match=r"xyz must have shape \(n, 3\) or \(3,\), not \(4,\)"):
        exactgeo.locate(sheet, [0, 0, 0, 0])
    with pytest.raises(ValueError, match=r"xyz must have shape \(n, 3\), not \(2, 2\)"):
        exactgeo.locate(sheet, [[0, 0], [1, 1]])
    with pytest.raises(ValueError, match="xyz must be real numbers"):
        exactgeo.locate(sheet, [["a", "b", "c"]])
    with pytest.raises(TypeError, match="mesh must be an exactgeo.Mesh"):
        exactgeo.locate(np.zeros((3, 3)), [0, 0, 0])
    with pytest.raises(TypeError, match="threads must be an integer"):
        exactgeo.locate(sheet, [0, 0, 0], threads=True)
    with pytest.raises(ValueError, match="threads must be at least 0"):
        exactgeo.locate(sheet, [0, 0, 0], threads=-1)


def test_agrees_with_trimesh():
    trimesh = pytest.importorskip("trimesh")
    pytest.importorskip("rtree", reason="trimesh.proximity needs rtree: pip install rtree")
    vertices, faces = bumpy_sheet(30)
    mesh = exactgeo.Mesh(vertices, faces)
    xyz = np.random.default_rng(8).uniform(-0.3, 1.3, size=(3000, 3))
    closest, distance, _ = trimesh.proximity.closest_point(trimesh.Trimesh(vertices, faces, process=False), xyz)
    points, distances = exactgeo.locate(mesh, xyz)
    np.testing.assert_allclose(distances, distance, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(exactgeo.point_position(mesh, points), closest, rtol=0, atol=1e-9)


def test_same_result_on_any_thread_count():
    mesh = exactgeo.Mesh(*bumpy_sheet(60))
    xyz = np.random.default_rng(5).uniform(-0.2, 1.2, size=(20000, 3))
    one = exactgeo.locate(mesh, xyz, threads=1)
    for threads in (None, 0, 3):
        points, distances = exactgeo.locate(mesh, xyz, threads=threads)
        np.testing.assert_array_equal(points.faces, one[0].faces)
        np.testing.assert_array_equal(points.barycentric, one[0].barycentric)
        np.testing.assert_array_equal(distances, one[1])


def test_the_gil_is_released_while_locating():
    big = exactgeo.Mesh(*bumpy_sheet(160))
    xyz = np.random.default_rng(6).uniform(-0.5, 1.5, size=(300000, 3))
    exactgeo.locate(big, xyz[:1])  # the face hierarchy is built once, outside the measurement
    duration, pause = longest_pause_of_python_while(lambda: exactgeo.locate(big, xyz, threads=1))
    assert pause < duration / 3, (duration, pause)


def test_located_points_are_sources_and_targets(sheet):
    # Points at the vertices are the vertices: as targets, the vertices' own distances.
    at_vertices, _ = exactgeo.locate(sheet, sheet.vertices[:40])
    np.testing.assert_array_equal(exactgeo.distance(sheet, 7, targets=at_vertices), exactgeo.distance(sheet, 7)[:40])
    # Points off the surface, as sources and as targets of the one-off calls and the solver: the distance
    # between two of them is the same both ways.
    points, _ = exactgeo.locate(sheet, np.random.default_rng(7).uniform(-0.2, 1.2, size=(6, 3)))
    between = np.array([exactgeo.distance(sheet, points[i], targets=points) for i in range(len(points))])
    np.testing.assert_allclose(between, between.T, rtol=0, atol=1e-12 * between.max())
    np.testing.assert_array_equal(np.diag(between), 0)
    from_all = exactgeo.GeodesicSolver(sheet).solve(points, targets=points).target_distances
    np.testing.assert_array_equal(from_all, 0)
    each = np.array([exactgeo.distance(sheet, points[i]) for i in range(len(points))])
    np.testing.assert_allclose(exactgeo.distance(sheet, points), each.min(axis=0), rtol=0, atol=1e-12 * each.max())
    path = exactgeo.path(sheet, points[0], points[1])
    assert path.length == pytest.approx(between[0, 1], rel=1e-12)
    np.testing.assert_allclose(path.points[-1], exactgeo.point_position(sheet, points[1]), atol=1e-12)
