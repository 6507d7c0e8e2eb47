"""Shortest paths: straight on a flat grid, length equal to the distance, locations that rebuild the points,
the command-line tool's paths, unreachable targets, and path queries on a solver."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import bumpy_sheet, read_json, run_cli, write_obj

import exactgeo


@pytest.fixture(scope="module")
def sheet():
    return exactgeo.Mesh(*bumpy_sheet(12))


def rebuilt_points(mesh: exactgeo.Mesh, path: exactgeo.GeodesicPath) -> np.ndarray:
    """The points as the weighted sums of mesh vertices the locations describe."""
    used = path.vertices >= 0
    corners = mesh.vertices[np.where(used, path.vertices, 0)]
    return (np.where(used, path.weights, 0.0)[:, :, None] * corners).sum(axis=1)


def test_on_a_flat_grid_the_path_is_the_straight_segment():
    mesh = exactgeo.Mesh(*exactgeo.make_grid(6, 4, 3.0, 2.0))
    start, end = mesh.vertices[0], mesh.vertices[34]
    path = exactgeo.path(mesh, 0, 34)
    assert path.length == pytest.approx(np.linalg.norm(end - start), rel=1e-14)
    np.testing.assert_allclose(path.points[0], start, atol=1e-15)
    np.testing.assert_allclose(path.points[-1], end, atol=1e-15)
    direction = (end - start) / np.linalg.norm(end - start)
    offsets = path.points - start
    np.testing.assert_allclose(offsets - np.outer(offsets @ direction, direction), 0, atol=1e-14)


def test_path_length_equals_the_distance(sheet):
    distances = exactgeo.distance(sheet, 7)
    for target in (0, 60, 120, 168):
        path = exactgeo.path(sheet, 7, target)
        assert path.length == pytest.approx(distances[target], rel=1e-9)
        segments = np.linalg.norm(np.diff(path.points, axis=0), axis=1).sum()
        assert segments == pytest.approx(distances[target], rel=1e-9)
        np.testing.assert_allclose(path.points[0], sheet.vertices[7], atol=1e-14)
        np.testing.assert_allclose(path.points[-1], sheet.vertices[target], atol=1e-14)


def test_locations_rebuild_the_points(sheet):
    target = exactgeo.SurfacePoint(200, (0.25, 0.25, 0.5))
    path = exactgeo.path(sheet, [3, 150], target)
    k = len(path.points)
    assert path.points.shape == path.vertices.shape == path.weights.shape == (k, 3)
    assert path.kind.shape == path.face.shape == (k,)
    assert set(path.kind) <= {"vertex", "edge", "face"}
    assert path.kind[-1] == "face" and path.face[-1] == 200
    assert (path.face[path.kind != "face"] == -1).all()
    np.testing.assert_allclose(path.weights.sum(axis=1), 1, atol=1e-14)
    np.testing.assert_allclose(rebuilt_points(sheet, path), path.points, atol=1e-14)
    np.testing.assert_allclose(path.points[-1], exactgeo.point_position(sheet, target), atol=1e-14)
    assert path.length == pytest.approx(exactgeo.distance(sheet, [3, 150], targets=target)[0], rel=1e-9)
    assert path.source in (0, 1)


def test_paths_match_the_command_line(cli, tmp_path, sheet):
    mesh_file = write_obj(tmp_path / "sheet.obj", sheet.vertices, sheet.faces)
    for target, text in ((150, "150"), (exactgeo.SurfacePoint(90, (0.1, 0.6, 0.3)), "90:0.1,0.6,0.3")):
        run_cli("path", mesh_file, "--source", 2, "--target", text, "--out", tmp_path / "p.json")
        expected = read_json(tmp_path / "p.json")
        path = exactgeo.path(sheet, 2, target)
        assert path.length == pytest.approx(expected["length"], rel=1e-13)
        np.testing.assert_allclose(path.points, expected["points"], atol=1e-13)
        assert len(expected["locations"]) == len(path.kind)
        for kind, vertices, location in zip(path.kind, path.vertices, expected["locations"]):
            if kind == "vertex":
                assert location["vertex"] == vertices[0]
            elif kind == "edge":
                assert location["edge"] == list(vertices[:2])


def test_an_unreachable_target_has_an_empty_path():
    mesh = exactgeo.Mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0], [5, 0, 0], [6, 0, 0], [5, 1, 0]], [[0, 1, 2], [3, 4, 5]])
    path = exactgeo.path(mesh, 0, 4)
    assert path.points.shape == (0, 3) and path.kind.shape == (0,)
    assert path.length == np.inf and path.source == -1


def test_reprs_of_paths_and_results_are_one_short_line():
    # A path across a fine grid has many points: its repr gives their number, the length and the ends, not
    # the arrays.
    mesh = exactgeo.Mesh(*exactgeo.make_grid(40, 40, 1.0, 1.0))
    path = exactgeo.path(mesh, 0, mesh.vertex_count - 21)  # the middle of the top edge
    assert len(path.points) > 40
    assert repr(path) == (
        f"exactgeo.GeodesicPath(points={len(path.points)}, length={path.length:.6g}, source=0, start=(0, 0, 0), "
        "end=(0.5, 1, 0))"
    )
    apart = exactgeo.Mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0], [5, 0, 0], [6, 0, 0], [5, 1, 0]], [[0, 1, 2], [3, 4, 5]])
    assert repr(exactgeo.path(apart, 0, 4)) == "exactgeo.GeodesicPath(points=0, length=inf, source=-1)"
    result = exactgeo.GeodesicSolver(apart).solve(0, targets=[1, 4])
    assert repr(result) == "exactgeo.GeodesicResult(vertices=6, largest_distance=1, inf=3, targets=2)"


def test_a_solver_answers_path_queries_about_its_last_run(sheet):
    solver = exactgeo.GeodesicSolver(sheet)
    with pytest.raises(ValueError, match="no run to trace a path in: solve first"):
        solver.path_to_vertex(0)
    result = solver.solve([10, 100], targets=[exactgeo.SurfacePoint(5, (0.3, 0.3, 0.4)), 44])
    for target in range(2):
        path = solver.path_to_target(target)
        assert path.length == pytest.approx(result.target_distances[target], rel=1e-9)
        assert path.source == result.target_nearest_source[target]
    with pytest.raises(ValueError, match=r"target 2 is out of range \(the last run had 2 targets\)"):
        solver.path_to_target(2)
    result = solver.solve([10, 100])
    path = solver.path_to_vertex(160)
    assert path.length == pytest.approx(result.distances[160], rel=1e-9)
    assert path.source == result.nearest_source[160]
    with pytest.raises(ValueError, match=r"vertex -1 is out of range \(mesh has 169 vertices\)"):
        solver.path_to_vertex(-1)


def test_several_targets_give_several_paths_from_one_run(sheet):
    paths = exactgeo.path(sheet, 0, [77, 150, 3])
    assert [p.length for p in paths] == [exactgeo.path(sheet, 0, t).length for t in (77, 150, 3)]
    points = exactgeo.path(sheet, 0, [exactgeo.SurfacePoint(5, (0.2, 0.3, 0.5)), 44])
    assert len(points) == 2
    assert points[1].length == pytest.approx(exactgeo.distance(sheet, 0)[44], rel=1e-12)


def test_a_path_gets_through_coincident_vertices():
    """Issue 34: vertices 2 and 3 coincide, an edge of zero length, and the path raised RuntimeError ("path
    tracing failed"). The surface is the flat triangle 0 1 2: the path is the straight segment."""
    mesh = exactgeo.Mesh([[0, 0, 0], [1, 0, 1], [0, 1, 2], [0, 1, 2]], [[0, 1, 2], [1, 3, 2]])
    for target in (2, 3):
        path = exactgeo.path(mesh, 0, target)
        assert path.length == pytest.approx(np.sqrt(5), rel=1e-12)
        assert path.vertices[-1, 0] == target


def test_a_target_at_a_split_vertex_is_that_vertex():
    """Issue 34: vertex 0 of a bowtie (two triangles meeting there only) is split into one copy per wing; as a
    target, by index or as the corner of either face, it stood on one face, and from the other wing got inf.
    It now has its per-vertex distance, straight along an edge, and a path as long."""
    vertices = np.array([[0, 0, 0], [3, 0, 0], [0, 4, 0], [-2, 0, 0], [0, 0, -1]], dtype=float)
    mesh = exactgeo.Mesh(vertices, [[0, 1, 2], [0, 3, 4]])
    at_zero = [0, exactgeo.SurfacePoint(0, (1, 0, 0)), exactgeo.SurfacePoint(1, (1, 0, 0))]
    for source in range(1, 5):
        along_edge = np.linalg.norm(vertices[source])
        solver = exactgeo.GeodesicSolver(mesh)
        result = solver.solve(source, targets=at_zero)
        assert result.distances[0] == pytest.approx(along_edge, rel=1e-15)
        np.testing.assert_array_equal(result.target_distances, result.distances[0])
        for target in range(len(at_zero)):
            assert solver.path_to_target(target).length == pytest.approx(along_edge, rel=1e-15)
    # A source at either corner of vertex 0 is vertex 0, in both wings.
    for corner in at_zero[1:]:
        np.testing.assert_allclose(exactgeo.distance(mesh, corner), np.linalg.norm(vertices, axis=1), rtol=1e-15)
