"""exactgeo.isolines on generated meshes, against closed forms and the error bound its docstring states."""

from __future__ import annotations

import numpy as np
import pytest

import exactgeo


def lengths(line: np.ndarray) -> np.ndarray:
    return np.linalg.norm(np.diff(line, axis=0), axis=1)


def test_flat_grid_points_lie_within_the_linear_interpolation_bound():
    # A flat square with the source at a corner: the exact distance is the Euclidean one, |p|. Along an edge
    # e at distance at least r from the source, |p| is convex with second derivative at most |e|^2 / r (in
    # the edge's parameter), so linear interpolation overestimates it by at most |e|^2 / (8 r): a crossing
    # point of level L has L - |e|^2 / (8 r) <= |p| <= L. The longest edges are the diagonals, |e| = h sqrt(2),
    # and r >= L - h sqrt(2) since one end of a crossed edge is at L or beyond.
    n = 20
    h = 1.0 / n
    vertices, faces = exactgeo.make_grid(n, n, 1.0, 1.0)
    mesh = exactgeo.Mesh(vertices, faces)
    d = exactgeo.distance(mesh, 0)
    np.testing.assert_allclose(d, np.linalg.norm(vertices, axis=1), rtol=1e-13, atol=1e-15)
    levels = [0.3, 0.55, 0.8, 0.95, 1.2]
    worst = 0.0
    for level, curves in zip(levels, exactgeo.isolines(mesh, d, levels)):
        assert len(curves) == 1  # one quarter circle: one polyline
        line = curves[0]
        bound = 2 * h**2 / (8 * (level - np.sqrt(2) * h))
        radius = np.linalg.norm(line, axis=1)
        assert radius.max() <= level + 1e-12
        assert (level - radius).max() <= bound
        worst = max(worst, (level - radius).max() / bound)
        assert line[:, 2].max() == 0
        # It runs from one side of the square to the other (or to the far sides beyond L = 1).
        ends = np.sort(line[[0, -1]], axis=0)
        assert min(ends[0]) == pytest.approx(0) or max(ends[1]) == pytest.approx(1)
        assert lengths(line).min() > 0
    assert worst > 0.5  # and it is nearly reached (0.83 of it at L = 0.8)


def test_a_loop_around_a_source_on_the_sphere_is_closed_and_as_long_as_the_circle():
    # On the unit sphere the points at distance L from a pole form a circle of length 2 pi sin(L). On the
    # icosphere both the distance and the chords differ from the sphere's by O(h^2): the measured relative
    # error is about 0.55 h^2 for subdivisions 2 to 5 (h the median edge length), so the tolerance is h^2.
    for subdivisions in (3, 4):
        vertices, faces = exactgeo.make_icosphere(subdivisions)
        mesh = exactgeo.Mesh(vertices, faces)
        h = float(np.median(np.linalg.norm(vertices[faces[:, 1]] - vertices[faces[:, 0]], axis=1)))
        d = exactgeo.distance(mesh, 0)
        levels = [0.5, 1.0, np.pi / 2, 2.5]
        for level, curves in zip(levels, exactgeo.isolines(mesh, d, levels)):
            assert len(curves) == 1
            loop = curves[0]
            np.testing.assert_array_equal(loop[0], loop[-1])  # closed: the first point repeated
            assert len(np.unique(loop[:-1], axis=0)) == len(loop) - 1  # and no point twice otherwise
            assert abs(lengths(loop).sum() / (2 * np.pi * np.sin(level)) - 1) <= h**2


def test_one_polyline_per_connected_curve():
    vertices, faces = exactgeo.make_grid(12, 12, 1.0, 1.0)
    mesh = exactgeo.Mesh(vertices, faces)
    d = exactgeo.distance(mesh, [0, 12])  # the corners (0, 0) and (1, 0)
    small, large = exactgeo.isolines(mesh, d, [0.3, 0.8])
    assert len(small) == 2 and len(large) == 1  # two quarter circles apart; then one curve around both
    # A closed curve inside the square: a source in the middle.
    d = exactgeo.distance(mesh, 6 * 13 + 6)
    (loop,) = exactgeo.isolines(mesh, d, 0.25)[0]
    np.testing.assert_array_equal(loop[0], loop[-1])
    # Two levels, two lists; a level outside the values, none.
    assert [len(c) for c in exactgeo.isolines(mesh, d, [0.1, 0.2, 5.0])] == [1, 1, 0]


def test_vertices_exactly_at_a_level_give_no_degenerate_or_doubled_segments():
    vertices, faces = exactgeo.make_grid(4, 4, 4.0, 4.0)  # integer coordinates
    mesh = exactgeo.Mesh(vertices, faces)
    x = vertices[:, 0]
    for values, level in [(x, 2.0), (x, 4.0), (-np.abs(x - 2), 0.0)]:  # a column of vertices; the edge; a ridge
        curves = exactgeo.isolines(mesh, values, [level])[0]
        assert len(curves) == 1, (values, level)
        line = curves[0]
        np.testing.assert_array_equal(line[:, 0], np.full(5, 2.0 if level != 4.0 else 4.0))
        np.testing.assert_array_equal(np.sort(line[:, 1]), np.arange(5.0))  # each vertex once, through the vertices
    assert exactgeo.isolines(mesh, x, [0.0]) == [[]]  # everything is at or above the level


def test_a_saddle_exactly_at_the_level_splits_the_curves_where_they_cross():
    vertices, faces = exactgeo.make_grid(4, 4, 4.0, 4.0)
    vertices[:, :2] -= 2  # the saddle x * y has its level set 0, the two axes, through the middle vertex
    mesh = exactgeo.Mesh(vertices, faces)
    curves = exactgeo.isolines(mesh, vertices[:, 0] * vertices[:, 1], [0.0])[0]
    assert len(curves) == 4  # four pieces from the middle to the sides
    for line in curves:
        assert len(line) == 3 and (line[:, 0] == 0).all() != (line[:, 1] == 0).all()
        assert [0, 0, 0] in line.tolist()


def test_faces_with_inf_are_left_out():
    vertices, faces = exactgeo.make_grid(10, 10, 1.0, 1.0)
    mesh = exactgeo.Mesh(vertices, faces)
    d = exactgeo.distance(mesh, 0, max_distance=0.6)
    (line,) = exactgeo.isolines(mesh, d, [0.5])[0]
    assert np.isfinite(line).all()
    assert exactgeo.isolines(mesh, d, [0.7]) == [[]]  # beyond the cut-off everything is inf
    values = np.where(vertices[:, 0] > 0.5, np.inf, vertices[:, 1])
    (line,) = exactgeo.isolines(mesh, values, [0.5])[0]
    assert line[:, 0].max() <= 0.5  # the curve y = 0.5 stops where the values are inf


def test_wrong_lengths_and_types_are_named():
    mesh = exactgeo.Mesh(*exactgeo.make_grid(2, 2, 1.0, 1.0))
    with pytest.raises(ValueError, match="got 8 values, but the mesh has 9 vertices"):
        exactgeo.isolines(mesh, np.zeros(8), [0.5])
    with pytest.raises(ValueError, match=r"got an array of shape \(9, 2\), but the mesh has 9 vertices"):
        exactgeo.isolines(mesh, np.zeros((9, 2)), [0.5])
    with pytest.raises(TypeError, match="must be an exactgeo.Mesh"):
        exactgeo.isolines("grid", np.zeros(9), [0.5])
