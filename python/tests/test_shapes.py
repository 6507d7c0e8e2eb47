"""Generated meshes and subdivision: the command line's built-in meshes vertex for vertex, closed-form
distances, and the library's checks."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import run_cli

import exactgeo


def test_grid_distances_are_euclidean():
    vertices, faces = exactgeo.make_grid(6, 3, 3.0, 1.5)
    assert vertices.shape == (28, 3) and faces.shape == (36, 3) and faces.dtype == np.uint32
    np.testing.assert_array_equal(vertices[3 * 7 + 2], [1.0, 1.5, 0.0])  # vertex (i, j) = j * (nx + 1) + i
    mesh = exactgeo.Mesh(vertices, faces)
    np.testing.assert_allclose(exactgeo.distance(mesh, 9), np.linalg.norm(vertices - vertices[9], axis=1), atol=1e-14)


def test_icosphere_distances_lie_between_chord_and_great_circle():
    vertices, faces = exactgeo.make_icosphere(3)
    assert len(faces) == 20 * 4**3
    np.testing.assert_allclose(np.linalg.norm(vertices, axis=1), 1, atol=1e-15)
    distances = exactgeo.distance(exactgeo.Mesh(vertices, faces), 0)
    chord = np.linalg.norm(vertices - vertices[0], axis=1)
    arc = 2 * np.arcsin(np.minimum(chord / 2, 1))
    assert (distances >= chord - 1e-12).all() and (distances <= arc + 1e-12).all()
    assert distances.max() == pytest.approx(np.pi, rel=0.02)


def test_the_built_in_meshes_match_the_command_line(cli, tmp_path):
    for name, (vertices, faces) in (
        ("@torus:24:12", exactgeo.make_bumpy_torus(24, 12)),
        ("@icosphere:2", exactgeo.make_icosphere(2)),
        ("@grid:5:4", exactgeo.make_grid(5, 4, 5.0, 4.0)),
    ):
        run_cli("distance", name, "--source", 3, "--out", tmp_path / "d.npy", "--quiet")
        np.testing.assert_array_equal(exactgeo.distance(exactgeo.Mesh(vertices, faces), 3), np.load(tmp_path / "d.npy"))


def test_subdivision_keeps_the_surface_and_the_original_vertices():
    vertices, faces = exactgeo.make_bumpy_torus(12, 8)
    finer_vertices, finer_faces = exactgeo.subdivide_midpoint(vertices.tolist(), faces.astype(np.int64))
    assert len(finer_faces) == 4 * len(faces)
    np.testing.assert_array_equal(finer_vertices[: len(vertices)], vertices)
    # The same surface: geodesic distances between the original vertices do not change.
    coarse = exactgeo.distance(exactgeo.Mesh(vertices, faces), 0)
    fine = exactgeo.distance(exactgeo.Mesh(finer_vertices, finer_faces), 0)[: len(vertices)]
    np.testing.assert_allclose(fine, coarse, rtol=1e-12)


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda: exactgeo.make_icosphere(-1), r"icosphere subdivisions -1 out of range \(0 to 13"),
        (lambda: exactgeo.make_icosphere(14), r"icosphere subdivisions 14 out of range \(0 to 13: 20 \* 4\^K faces"),
        (lambda: exactgeo.make_bumpy_torus(2, 8), r"bumpy torus needs at least 3 segments each way \(got 2 x 8\)"),
        (lambda: exactgeo.make_grid(0, 3, 1.0, 1.0), "grid needs at least 1 x 1 squares"),
        (lambda: exactgeo.subdivide_midpoint([[0, 0, 0]], [[0, 0, 1]]), "subdivide_midpoint: face 0 vertex index 1"),
    ],
)
def test_bad_shape_parameters_raise_valueerror(call, message):
    with pytest.raises(ValueError, match=message):
        call()


@pytest.mark.parametrize(
    ("call", "error", "message"),
    [
        (lambda: exactgeo.make_icosphere(2**40), ValueError, "subdivisions must be at most 2147483647, not 10995"),
        (lambda: exactgeo.make_icosphere(1.5), TypeError, "subdivisions must be an integer, not 1.5"),
        (lambda: exactgeo.make_bumpy_torus(2**40, 8), ValueError, "major_segments must be at most 2147483647"),
        (lambda: exactgeo.make_bumpy_torus(8, "8"), TypeError, "minor_segments must be an integer, not '8'"),
        (lambda: exactgeo.make_grid(3, -(2**40), 1.0, 1.0), ValueError, "ny must be at least -2147483648"),
    ],
)
def test_shape_sizes_that_are_no_c_int_are_named(call, error, message):
    # These printed nanobind's list of the accepted signatures.
    with pytest.raises(error, match=message):
        call()
