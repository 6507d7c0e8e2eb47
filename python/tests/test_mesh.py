"""Building meshes: accepted dtypes and layouts, the views, the report, loading files, and rejected input."""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import pytest
from conftest import REPOSITORY, run_cli, shared_mesh, write_obj

import exactgeo


def test_the_tests_use_the_installed_package():
    package = Path(exactgeo.__file__).resolve()
    assert REPOSITORY / "python" not in package.parents, (
        f"imported the source tree at {package}, not the installed package"
    )


def test_stubs_and_typed_marker_are_installed():
    package = Path(exactgeo.__file__).parent
    assert (package / "py.typed").is_file()
    stub = (package / "_core.pyi").read_text()
    assert "class GeodesicSolver" in stub and "def fill_distance_matrix" in stub


def test_arrays_of_every_dtype_and_order_give_the_same_mesh():
    vertices, faces = exactgeo.make_grid(4, 4, 2.0, 1.0)  # coordinates are multiples of 1/4
    reference = exactgeo.distance(exactgeo.Mesh(vertices, faces), 0)
    variants = [
        (vertices.astype(np.float32), faces),
        (vertices, faces.astype(np.int64)),
        (vertices, faces.astype(np.uint32)),
        (vertices, faces.astype(np.uint16)),
        (vertices, faces.astype(np.float64)),  # whole numbers stored as floats
        (np.asfortranarray(vertices), np.asfortranarray(faces)),
        (vertices[:, ::-1][:, ::-1], faces[::1]),  # strided views
        (vertices.tolist(), faces.tolist()),
        ((vertices * 4).astype(np.int32), faces),  # integer coordinates: the grid scaled by 4
    ]
    for v, f in variants:
        mesh = exactgeo.Mesh(v, f)
        expected = reference * 4 if np.asarray(v).dtype.kind == "i" else reference
        rtol = 1e-6 if np.asarray(v).dtype == np.float32 else 1e-14
        np.testing.assert_allclose(exactgeo.distance(mesh, 0), expected, rtol=rtol, atol=1e-12)


def test_views_are_the_mesh_storage_read_only():
    vertices, faces = exactgeo.make_grid(2, 2, 1.0, 1.0)
    mesh = exactgeo.Mesh(vertices.astype(np.float32), faces.astype(np.int64))
    assert mesh.vertex_count == 9 and mesh.face_count == 8
    assert mesh.vertices.dtype == np.float64 and mesh.vertices.shape == (9, 3)
    assert mesh.faces.dtype == np.uint32 and mesh.faces.shape == (8, 3)
    np.testing.assert_array_equal(mesh.faces, faces)
    np.testing.assert_array_equal(mesh.vertices, vertices.astype(np.float32))
    with pytest.raises(ValueError):
        mesh.vertices[0, 0] = 5.0
    view = mesh.faces
    del mesh
    assert view.sum() == faces.sum()  # the view keeps the mesh alive


@pytest.mark.parametrize("cells", [3, 150])  # 150 x 150: built on a worker thread, on the cores
@pytest.mark.parametrize("index_dtype", [np.int32, np.uint32])
def test_the_mesh_keeps_its_own_copy_of_the_callers_arrays(cells, index_dtype):
    # float64 and 32-bit indices reach the library without a conversion in Python: the mesh copies them, so
    # that writing over the caller's arrays afterwards cannot change it.
    vertices, faces = exactgeo.make_grid(cells, cells, 2.0, 1.0)
    vertices, faces = np.ascontiguousarray(vertices, dtype=np.float64), np.ascontiguousarray(faces, dtype=index_dtype)
    kept_vertices, kept_faces = vertices.copy(), faces.copy()
    mesh = exactgeo.Mesh(vertices, faces)
    vertices[:] = 7.0
    faces[:] = 0
    np.testing.assert_array_equal(mesh.vertices, kept_vertices)
    np.testing.assert_array_equal(mesh.faces, kept_faces)
    far = (cells + 1) ** 2 - 1
    assert exactgeo.distance(mesh, 0)[far] == pytest.approx(np.hypot(2.0, 1.0), rel=1e-14)


def test_report_counts_what_validation_found():
    # Two triangles sharing an edge, one triangle repeating a vertex (dropped), one vertex used by nothing.
    vertices = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0], [5, 5, 5]]
    faces = [[0, 1, 2], [1, 3, 2], [0, 0, 1]]
    report = exactgeo.Mesh(vertices, faces).report
    assert report.faces == 3 and report.faces_used == 2
    assert report.faces_repeating_a_vertex == 1
    assert report.unreferenced_vertices == 1
    assert report.boundary_edges == 4 and report.components == 1


def test_report_matches_the_command_line(cli):
    path = shared_mesh("beetle")  # non-manifold edges, boundaries, several components
    expected = json.loads(run_cli("info", path, "--json").stdout)
    report = exactgeo.Mesh.load(path).report.to_dict()
    assert report == {name: expected[name] for name in report}
    assert set(report) == set(expected) - {"mesh"}


@pytest.mark.filterwarnings("ignore:.*vertices are unreachable:UserWarning")  # the unwelded run, on purpose
def test_load_reads_files_and_weld_merges_seams(tmp_path):
    vertices, faces = exactgeo.make_grid(3, 3, 1.0, 1.0)
    path = write_obj(tmp_path / "grid.obj", vertices, faces)
    mesh = exactgeo.Mesh.load(path)
    np.testing.assert_array_equal(mesh.vertices, vertices)
    np.testing.assert_array_equal(mesh.faces, faces)
    assert exactgeo.Mesh.load(str(path)).face_count == len(faces)

    # The same square as two triangles that share no vertex index: a seam.
    seam = write_obj(
        tmp_path / "seam.obj",
        np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0.0]]),
        np.array([[0, 1, 2], [3, 4, 5]]),
    )
    assert np.isinf(exactgeo.distance(exactgeo.Mesh.load(seam), 0)[4])
    welded = exactgeo.Mesh.load(seam, weld_duplicate_positions=True)
    assert welded.report.welded_vertices == 2
    assert exactgeo.distance(welded, 0)[4] == pytest.approx(np.sqrt(2))


def test_unreadable_files_raise_oserror_and_malformed_ones_valueerror(tmp_path):
    with pytest.raises(OSError, match="cannot open"):
        exactgeo.Mesh.load(tmp_path / "missing.obj")
    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n")
    with pytest.raises(ValueError, match="bad.obj"):
        exactgeo.Mesh.load(bad)


def test_load_takes_str_bytes_and_path_like_names_not_utf8_ones_included(tmp_path):
    # Bytes printed nanobind's list of signatures; a str name that is not UTF-8 could not reach the library.
    name = os.fsencode(tmp_path) + b"/sphere-\xff.obj"
    vertices, faces = exactgeo.make_icosphere(1)
    write_obj(Path(os.fsdecode(name)), vertices, faces)
    for path in (name, os.fsdecode(name), Path(os.fsdecode(name))):
        assert exactgeo.Mesh.load(path).face_count == 80
    with pytest.raises(OSError, match=r"missing-\\xff\.obj"):
        exactgeo.Mesh.load(os.fsencode(tmp_path) + b"/missing-\xff.obj")
    with pytest.raises(TypeError, match="path must be a str, bytes or os.PathLike, not int"):
        exactgeo.Mesh.load(3)


def test_mesh_arguments_of_the_wrong_kind_are_named(tmp_path):
    vertices, faces = exactgeo.make_icosphere(1)
    sphere = write_obj(tmp_path / "sphere.obj", vertices, faces)
    for build in (lambda **kw: exactgeo.Mesh(vertices, faces, **kw), lambda **kw: exactgeo.Mesh.load(sphere, **kw)):
        with pytest.raises(TypeError, match="threads must be an integer, not 1.5"):
            build(threads=1.5)
        with pytest.raises(ValueError, match="threads must be at least 0, not -1"):
            build(threads=-1)
        with pytest.raises(ValueError, match="threads must be at most 4294967295, not 1099511627776"):
            build(threads=2**40)
        # "no" was taken for true, and the mesh welded.
        with pytest.raises(TypeError, match="weld_duplicate_positions must be True or False, not 'no'"):
            build(weld_duplicate_positions="no")
        assert build(weld_duplicate_positions=np.True_, threads=np.uint8(0)).face_count == 80


SQUARE = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]]


@pytest.mark.parametrize(
    ("vertices", "faces", "message"),
    [
        # Messages written by the library (C++ exactgeo::Error), word for word.
        ([[0, 0, 0], [1, 0, 0], [0, 1, np.nan]], [[0, 1, 2]], "vertex 2 has a non-finite coordinate"),
        ([[0, 0, 0], [1, 0, 0], [np.inf, 1, 0]], [[0, 1, 2]], "vertex 2 has a non-finite coordinate"),
        (SQUARE, [[0, 1, 2], [1, 3, 4]], "face 1 names vertex 4, but the mesh has 4 vertices"),
        (SQUARE, np.zeros((0, 3), dtype=int), "mesh has no faces"),
        (SQUARE, [[0, 0, 1]], "mesh has no usable face"),
        # Values the library cannot receive, in its wording.
        (SQUARE, [[0, 1, 2], [1, 3, -1]], "face 1 names vertex -1, but the mesh has 4 vertices"),
        (SQUARE, np.array([[0, 1, 2], [1, 3, 2**40]]), f"face 1 names vertex {2**40}, but the mesh has 4 vertices"),
        (SQUARE, np.array([[0, 1, -3]], dtype=np.int8), "face 0 names vertex -3, but the mesh has 4 vertices"),
        (
            SQUARE,
            np.array([[0, 1, 2**33]], dtype=np.uint64),
            f"face 0 names vertex {2**33}, but the mesh has 4 vertices",
        ),
        (SQUARE, np.array([[0, 1, -1.0]]), "face 0 names vertex -1, but the mesh has 4 vertices"),
        # Conversions that would lose something.
        (SQUARE, [[0, 1, 2.5]], "faces must be whole numbers: face 0 names vertex 2.5"),
        (SQUARE, [[0, 1, np.nan]], "faces must be whole numbers: face 0 names vertex nan"),
        (SQUARE, [[True, False, True]], "faces must be integer indices, not booleans"),
        (SQUARE, [["0", "1", "2"]], "faces must be integer indices, not dtype <U1"),
        (SQUARE, [[0, 1]], r"faces must have shape \(n, 3\), not \(1, 2\)"),
        (SQUARE, [0, 1, 2], r"faces must have shape \(n, 3\), not \(3,\)"),
        ([[0, 0, 0, 0], [1, 0, 0, 0], [0, 1, 0, 0]], [[0, 1, 2]],
         r"vertices must have shape \(n, 3\), or \(n, 2\) for z = 0, not \(3, 4\)"),
        ([0, 0, 1], [[0, 1, 2]], r"vertices must have shape \(n, 3\), or \(n, 2\) for z = 0, not \(3,\)"),
        ([[0, 0], [1, 0], [0, 1j]], [[0, 1, 2]], "vertices must be real numbers, not dtype complex128"),
        ([[0, 0, 1j], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]], "vertices must be real numbers, not dtype complex128"),
    ],
)
def test_bad_meshes_raise_valueerror_naming_the_element(vertices, faces, message):
    with pytest.raises(ValueError, match=message):
        exactgeo.Mesh(vertices, faces)


@pytest.mark.parametrize("not_a_mesh", [None, np.zeros((3, 3))])
def test_anything_but_a_mesh_is_named_with_the_fix(not_a_mesh):
    for call in (
        lambda: exactgeo.distance(not_a_mesh, 0),
        lambda: exactgeo.path(not_a_mesh, 0, 1),
        lambda: exactgeo.distance_matrix(not_a_mesh, [0]),
        lambda: exactgeo.farthest_point_sampling(not_a_mesh, 3),
        lambda: exactgeo.vertex_point(not_a_mesh, 0),
    ):
        with pytest.raises(TypeError, match=r"mesh must be an exactgeo.Mesh, not \w+: build one with exactgeo.Mesh"):
            call()


def test_surface_point_arguments_are_named():
    with pytest.raises(TypeError, match="SurfacePoint: face must be an integer face index, not 1.5"):
        exactgeo.SurfacePoint(1.5, (1, 0, 0))
    with pytest.raises(TypeError, match="SurfacePoint: barycentric must be three real numbers"):
        exactgeo.SurfacePoint(1, ("a", 0, 0))


def test_meshes_and_solvers_pickle_for_other_processes(tmp_path):
    import multiprocessing
    import pickle

    vertices, faces = exactgeo.make_bumpy_torus(24, 10)
    for weld in (False, True):
        mesh = exactgeo.Mesh(vertices, faces, weld_duplicate_positions=weld)
        copy = pickle.loads(pickle.dumps(mesh))
        np.testing.assert_array_equal(copy.vertices, mesh.vertices)
        np.testing.assert_array_equal(copy.faces, mesh.faces)
        assert copy.report == mesh.report
        np.testing.assert_array_equal(exactgeo.distance(copy, 3), exactgeo.distance(mesh, 3))
    solver = pickle.loads(pickle.dumps(exactgeo.GeodesicSolver(mesh)))
    np.testing.assert_array_equal(solver.solve(3).distances, exactgeo.distance(mesh, 3))
    with multiprocessing.get_context("spawn").Pool(2) as pool:
        rows = pool.starmap(exactgeo.distance, [(mesh, s) for s in (0, 5)])
    for source, row in zip((0, 5), rows):
        np.testing.assert_array_equal(row, exactgeo.distance(mesh, source))


def test_a_process_unpickling_the_same_mesh_again_builds_it_once():
    import pickle

    vertices, faces = exactgeo.make_bumpy_torus(24, 10)
    mesh = exactgeo.Mesh(vertices, faces)
    data = pickle.dumps(mesh)
    first = pickle.loads(data)
    assert pickle.loads(data) is first  # a task after another on the same worker: no second build
    assert pickle.loads(pickle.dumps(mesh)) is first  # the original pickled again: the same identity
    assert pickle.loads(pickle.dumps(first)) is first  # passed on from that worker: still the same mesh
    other = pickle.loads(pickle.dumps(exactgeo.Mesh(vertices, faces)))  # equal arrays, another mesh
    assert other is not first and other.report == first.report
    welded = pickle.loads(pickle.dumps(exactgeo.Mesh(vertices, faces, weld_duplicate_positions=True)))
    assert welded is not first and welded._weld


def test_polygons_are_fan_triangulated_like_the_file_readers(tmp_path):
    vertices = [[0, 0, 0], [1, 0, 0], [2, 0, 0], [2, 1, 0], [1, 1, 0], [0, 1, 0], [1, 2, 0]]
    quads_and_a_triangle = [[0, 1, 4, 5], [1, 2, 3, 4], [5, 4, 6]]
    path = tmp_path / "mixed.obj"
    path.write_text(
        "".join(f"v {x} {y} {z}\n" for x, y, z in vertices)
        + "".join("f " + " ".join(str(i + 1) for i in face) + "\n" for face in quads_and_a_triangle)
    )
    loaded = exactgeo.Mesh.load(path)
    built = exactgeo.Mesh(vertices, quads_and_a_triangle)
    np.testing.assert_array_equal(built.faces, loaded.faces)
    quads = exactgeo.Mesh(vertices, np.array(quads_and_a_triangle[:2]))  # an (m, 4) array
    np.testing.assert_array_equal(quads.faces, loaded.faces[:4])
    with pytest.raises(ValueError, match="face 1 has 2 vertices; a face needs at least 3"):
        exactgeo.Mesh(vertices, [[0, 1, 4], [1, 2]])
    with pytest.raises(ValueError, match="face 1 names vertex 9, but the mesh has 7 vertices"):
        exactgeo.Mesh(vertices, [[0, 1, 4, 5], [1, 2, 9]])


def test_planar_vertices_are_taken_at_z_0():
    planar = [[0, 0], [1, 0], [0, 1], [1, 1]]
    faces = [[0, 1, 2], [1, 3, 2]]
    mesh = exactgeo.Mesh(np.array(planar, dtype=np.int32), faces)
    np.testing.assert_array_equal(mesh.vertices, [[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]])
    np.testing.assert_array_equal(exactgeo.distance(mesh, 0), exactgeo.distance(exactgeo.Mesh(mesh.vertices, faces), 0))
    vertices, _ = exactgeo.subdivide_midpoint(planar, faces)
    assert vertices.shape == (9, 3) and not vertices[:, 2].any()


def test_seams_that_cut_the_surface_are_pointed_out_with_the_fix(tmp_path):
    # Two triangles sharing an edge by position only, as trimesh leaves a mesh split at a texture seam.
    vertices = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]
    faces = [[0, 1, 2], [3, 4, 5]]
    # Each way into the solver warns at this file's line, not at exactgeo's.
    mesh = exactgeo.Mesh(vertices, faces)
    for call in (lambda: exactgeo.distance(mesh, 0), lambda: exactgeo.GeodesicSolver(mesh).solve(0)):
        unreachable = r"3 of 6 vertices are unreachable.*weld_duplicate_positions=True"
        with pytest.warns(UserWarning, match=unreachable) as caught:
            call()
        assert [w.filename for w in caught] == [__file__]
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        welded = exactgeo.distance(exactgeo.Mesh(vertices, faces, weld_duplicate_positions=True), 0)
        assert np.isfinite(welded).all()
        exactgeo.distance(exactgeo.Mesh(vertices, faces), 0, max_distance=0.5)  # a cut-off explains inf
    path = write_obj(tmp_path / "seam.obj", np.array(vertices, float), np.array(faces))
    assert "--weld" in run_cli("distance", path, "--source", "0").stderr
    assert "warning" not in run_cli("distance", path, "--source", "0", "--weld").stderr
